// A decoding worker of the page (crates/web/src/stream.rs): it instantiates
// the page's own wasm module (posted to it compiled, with `init`), then
// reads pages of a streamed store (the two chunk fetches, crc32c checks and
// gzip inflates: `strataWorkerRead`) and posts their planes back as
// transferred buffers. `abort` stops a read (the camera moved on, or its
// timeout).
import init, { strataWorkerRead } from "./pkg/strata_web.js";

let ready = null;
const flights = new Map();

self.onmessage = async (event) => {
  const m = event.data;
  if (m.kind === "init") {
    ready = init({ module_or_path: m.module }).then(
      () => self.postMessage({ kind: "ready" }),
      (e) => self.postMessage({ kind: "failed", error: String(e) }),
    );
    return;
  }
  if (m.kind === "abort") {
    const controller = flights.get(m.id);
    if (controller) controller.abort();
    return;
  }
  // kind === "read"
  const controller = new AbortController();
  flights.set(m.id, controller);
  let answer;
  try {
    await ready;
    answer = await strataWorkerRead(m.base, m.level, m.cx, m.cy, m.timeoutMs, controller.signal);
  } catch (e) {
    answer = { error: "the decoding worker failed: " + String(e), bytes: 0 };
  }
  flights.delete(m.id);
  answer.kind = "read";
  answer.id = m.id;
  const transfer = answer.heights ? [answer.heights.buffer, answer.metas.buffer] : [];
  self.postMessage(answer, transfer);
};
