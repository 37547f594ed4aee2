//! Where finished frames go: piped to `ffmpeg` as raw RGBA and encoded to
//! H.264 MP4, or written as numbered PNGs.
//!
//! The MP4 is fragmented (a fragment per second), so when ffmpeg stops
//! half-way the frames it already wrote stay playable in the file.

use anyhow::{Context, bail};
use image::RgbaImage;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::thread::JoinHandle;

/// How to install what `strata video` needs to write MP4.
pub const FFMPEG_HINT: &str = "install it (Debian/Ubuntu: `apt-get install ffmpeg`) or pass \
                               --frames-dir DIR to write numbered PNGs instead";

/// A destination for frames of one size.
pub trait FrameSink {
    fn write(&mut self, frame: &RgbaImage) -> anyhow::Result<()>;
    /// Flush and close; what was written, in words.
    fn finish(self: Box<Self>) -> anyhow::Result<String>;
}

/// Is `ffmpeg` on the PATH? Checked before any GPU work.
pub fn check_ffmpeg() -> anyhow::Result<()> {
    match Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
    {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            bail!("`ffmpeg` is not on the PATH: {FFMPEG_HINT}")
        }
        Err(e) => Err(e).context("running `ffmpeg -version`"),
    }
}

/// `ffmpeg` reading raw RGBA frames on stdin.
pub struct Ffmpeg {
    child: Child,
    stdin: Option<ChildStdin>,
    /// Collects ffmpeg's stderr on a thread, so a chatty ffmpeg never
    /// blocks on a full pipe while we block writing a frame.
    stderr: Option<JoinHandle<String>>,
    out: PathBuf,
    size: (u32, u32),
    frames: u32,
}

impl Ffmpeg {
    pub fn start(out: &Path, width: u32, height: u32, fps: u32) -> anyhow::Result<Ffmpeg> {
        if !width.is_multiple_of(2) || !height.is_multiple_of(2) {
            bail!("H.264 needs an even frame size; {width}x{height} is not");
        }
        let mut child = Command::new("ffmpeg")
            .args(["-hide_banner", "-loglevel", "error", "-y"])
            .args(["-f", "rawvideo", "-pix_fmt", "rgba"])
            .args(["-s", &format!("{width}x{height}"), "-r", &fps.to_string()])
            .args(["-i", "-"])
            .args([
                "-c:v", "libx264", "-pix_fmt", "yuv420p", "-preset", "veryfast",
            ])
            .args(["-crf", "23", "-g", &fps.to_string()])
            .args(["-movflags", "frag_keyframe+empty_moov+default_base_moof"])
            .arg(out)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::NotFound {
                    anyhow::anyhow!("`ffmpeg` is not on the PATH: {FFMPEG_HINT}")
                } else {
                    anyhow::Error::new(e).context("starting ffmpeg")
                }
            })?;
        let stdin = child.stdin.take();
        let stderr = child.stderr.take().map(|mut pipe| {
            std::thread::spawn(move || {
                let mut text = String::new();
                let _ = pipe.read_to_string(&mut text);
                text
            })
        });
        Ok(Ffmpeg {
            child,
            stdin,
            stderr,
            out: out.to_path_buf(),
            size: (width, height),
            frames: 0,
        })
    }

    /// Close stdin, wait for ffmpeg, and return its status and stderr.
    fn close(&mut self) -> (Option<std::process::ExitStatus>, String) {
        // Closing stdin tells ffmpeg the video is over.
        self.stdin = None;
        let status = self.child.wait().ok();
        let text = self
            .stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        (status, text.trim().to_string())
    }

    fn failed(&mut self, what: &str) -> anyhow::Error {
        let (status, stderr) = self.close();
        let status = status.map_or("no exit status".to_string(), |s| s.to_string());
        anyhow::anyhow!(
            "ffmpeg {what} after {} frame(s) ({status}); the frames it encoded so far are kept in {} \
             (a fragmented MP4, playable up to the last whole second). ffmpeg said:\n{}",
            self.frames,
            self.out.display(),
            if stderr.is_empty() {
                "(nothing)"
            } else {
                &stderr
            }
        )
    }
}

impl FrameSink for Ffmpeg {
    fn write(&mut self, frame: &RgbaImage) -> anyhow::Result<()> {
        if frame.dimensions() != self.size {
            bail!(
                "frame is {:?}, the encoder was started for {:?}",
                frame.dimensions(),
                self.size
            );
        }
        let Some(stdin) = self.stdin.as_mut() else {
            return Err(self.failed("is closed"));
        };
        if stdin.write_all(frame.as_raw()).is_err() {
            return Err(self.failed("stopped"));
        }
        self.frames += 1;
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> anyhow::Result<String> {
        if let Some(mut stdin) = self.stdin.take() {
            let _ = stdin.flush();
        }
        let (status, stderr) = self.close();
        match status {
            Some(s) if s.success() => Ok(format!(
                "{} frames encoded to {}",
                self.frames,
                self.out.display()
            )),
            _ => {
                self.stdin = None;
                Err(anyhow::anyhow!(
                    "ffmpeg failed at the end ({}) after {} frame(s); output kept in {}. ffmpeg said:\n{}",
                    status.map_or("no exit status".to_string(), |s| s.to_string()),
                    self.frames,
                    self.out.display(),
                    stderr
                ))
            }
        }
    }
}

impl Drop for Ffmpeg {
    fn drop(&mut self) {
        // An error elsewhere dropped us mid-video: end ffmpeg cleanly so the
        // fragments so far are flushed, rather than leaving it waiting.
        if self.stdin.is_some() || self.stderr.is_some() {
            let _ = self.close();
        }
    }
}

/// Numbered PNGs (`frame-00000.png`, ...) in a directory, encoded on a
/// thread of their own so compressing one frame overlaps rendering the next.
pub struct PngDir {
    dir: PathBuf,
    frames: u32,
    queue: Option<std::sync::mpsc::SyncSender<(PathBuf, RgbaImage)>>,
    writer: Option<JoinHandle<anyhow::Result<()>>>,
}

/// Frames waiting for the PNG writer before `write` blocks.
const PNG_QUEUE: usize = 4;

impl PngDir {
    pub fn create(dir: &Path) -> anyhow::Result<PngDir> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the frames directory {}", dir.display()))?;
        let (queue, frames) = std::sync::mpsc::sync_channel::<(PathBuf, RgbaImage)>(PNG_QUEUE);
        let writer = std::thread::spawn(move || {
            for (path, frame) in frames {
                frame
                    .save(&path)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
            Ok(())
        });
        Ok(PngDir {
            dir: dir.to_path_buf(),
            frames: 0,
            queue: Some(queue),
            writer: Some(writer),
        })
    }

    pub fn frame_path(dir: &Path, index: u32) -> PathBuf {
        dir.join(format!("frame-{index:05}.png"))
    }

    /// Stop the writer and return its first error, if any.
    fn join(&mut self) -> anyhow::Result<()> {
        drop(self.queue.take());
        match self.writer.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(anyhow::anyhow!("the PNG writer thread panicked")),
            None => Ok(()),
        }
    }
}

impl FrameSink for PngDir {
    fn write(&mut self, frame: &RgbaImage) -> anyhow::Result<()> {
        let path = Self::frame_path(&self.dir, self.frames);
        let sent = self
            .queue
            .as_ref()
            .is_some_and(|q| q.send((path, frame.clone())).is_ok());
        if !sent {
            // The writer stopped: its error says why.
            self.join()?;
            anyhow::bail!("the PNG writer stopped");
        }
        self.frames += 1;
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> anyhow::Result<String> {
        self.join()?;
        Ok(format!(
            "{} frames written to {} (frame-00000.png ...)",
            self.frames,
            self.dir.display()
        ))
    }
}

impl Drop for PngDir {
    fn drop(&mut self) {
        // Stopped by an error elsewhere: the queued frames are still written.
        let _ = self.join();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_frames_are_numbered_and_all_written() {
        let dir = std::env::temp_dir().join(format!("strata-pngdir-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let mut sink: Box<dyn FrameSink> = Box::new(PngDir::create(&dir).unwrap());
        for i in 0..10u8 {
            sink.write(&RgbaImage::from_pixel(4, 2, image::Rgba([i, 0, 0, 255])))
                .unwrap();
        }
        assert!(sink.finish().unwrap().starts_with("10 frames"));
        let last = image::open(PngDir::frame_path(&dir, 9)).unwrap().to_rgba8();
        assert_eq!(last.get_pixel(0, 0).0, [9, 0, 0, 255]);
        assert!(!PngDir::frame_path(&dir, 10).exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
