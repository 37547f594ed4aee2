//! URL parameters, the world in the page (generated, fetched or picked),
//! the progress bar.

use crate::progress::{progress, yield_to_browser};
use anyhow::{Context, bail};
use strata_level::World;
use strata_level::generate::{GenerateParams, Generation, parse_size};
use strata_render::MethodSettings;
use strata_render::methods::METHODS;
use strata_viewer::web::{Backend, now_ms, set_state};
use wasm_bindgen::JsCast;
use wasm_bindgen_futures::JsFuture;

/// What the URL asks for.
pub struct Params {
    pub backend: Backend,
    pub method: String,
    pub view: Option<String>,
    pub size: (u32, u32),
    pub scale: Option<f32>,
    pub world: GenerateParams,
    pub level: Option<String>,
    /// `?NAME=SETTING` (`?voxel=X,Y,Z`, `?ray=64`): a method's knobs in
    /// `--methods NAME:SETTING`'s form (default the tuned ones).
    pub settings: MethodSettings,
    /// `?compare`: run the quick protocol instead of the viewer.
    pub compare: bool,
    /// `&views=A,B`: the protocol's views (default: the level's).
    pub views: Option<Vec<String>>,
    /// `&methods=A,B:setting`: the protocol's methods (default: every one).
    pub methods: Option<String>,
    /// `?gpu-budget=MIB`: the paged terrain's GPU budget for a streamed store.
    pub gpu_budget: u64,
    /// `?chunk-timeout-ms=MS`, `?decode=worker|main`: how a streamed store's chunks are read.
    pub pump: crate::stream::PumpOptions,
}

/// The paged terrain's GPU budget in the page by default: well inside
/// WebGPU's default limits (an atlas of 2048x2048-texel layers, 128 MiB per
/// storage binding), and what a CPU adapter (SwiftShader) holds easily.
pub const DEFAULT_GPU_BUDGET_MIB: u64 = 64;

impl Params {
    pub fn from_url() -> anyhow::Result<Params> {
        let search = web_sys::window()
            .context("no window")?
            .location()
            .search()
            .map_err(|_| anyhow::anyhow!("cannot read the page's URL"))?;
        let query = web_sys::UrlSearchParams::new_with_str(&search)
            .map_err(|_| anyhow::anyhow!("cannot parse the page's URL parameters"))?;
        let get = |name: &str| query.get(name).filter(|v| !v.is_empty());
        let backend = match get("backend").as_deref() {
            None | Some("webgpu") => Backend::WebGpu,
            Some("webgl2") => Backend::WebGl2,
            Some(other) => bail!("?backend={other}: use webgpu (default) or webgl2"),
        };
        let size = match get("size") {
            Some(text) => parse_size(&text).with_context(|| format!("?size={text}"))?,
            None => (960, 600),
        };
        if !(1..=8192).contains(&size.0) || !(1..=8192).contains(&size.1) {
            bail!("?size: each side 1..=8192 pixels");
        }
        let scale = match get("scale") {
            Some(text) => Some(
                text.parse::<f32>()
                    .ok()
                    .filter(|s| *s > 0.0 && *s <= 4.0)
                    .with_context(|| format!("?scale={text}: a number in (0, 4]"))?,
            ),
            None => None,
        };
        let mut world = GenerateParams::default();
        if let Some(text) = get("world") {
            (world.width, world.height) =
                parse_size(&text).with_context(|| format!("?world={text}"))?;
        }
        if let Some(text) = get("seed") {
            world.seed = text
                .parse()
                .ok()
                .with_context(|| format!("?seed={text}: a whole number"))?;
        }
        // `?NAME=SETTING`: a method's knobs, in `--methods NAME:SETTING`'s
        // form (`?voxel=2,4,1`, `?ray=64`, `?mesh=0.75`).
        let mut settings = MethodSettings::default();
        for m in METHODS {
            if let Some(text) = get(m.name) {
                m.apply_setting(&text, &mut settings)
                    .with_context(|| format!("?{}={text}: {}", m.name, m.knobs.grammar))?;
            }
        }
        let gpu_budget = match get("gpu-budget") {
            Some(text) => text
                .parse::<u64>()
                .ok()
                .filter(|m| (1..=4096).contains(m))
                .with_context(|| format!("?gpu-budget={text}: MiB, 1..=4096"))?,
            None => DEFAULT_GPU_BUDGET_MIB,
        } << 20;
        let pump = crate::stream::PumpOptions::parse(get("chunk-timeout-ms"), get("decode"))?;
        Ok(Params {
            gpu_budget,
            pump,
            backend,
            settings,
            method: get("method").unwrap_or_else(|| "ray".into()),
            view: get("view"),
            size,
            scale,
            world,
            level: get("level"),
            compare: query.has("compare"),
            views: get("views").map(|v| v.split(',').map(|n| n.trim().to_string()).collect()),
            methods: get("methods"),
        })
    }
}

/// Read the URL, get the world, start the viewer.
pub async fn run() -> anyhow::Result<()> {
    let params = Params::from_url()?;
    if let Some(url) = &params.level
        && !params.compare
    {
        let base = with_slash(url);
        progress(Some(0.0), &format!("opening {base}"));
        let start = now_ms();
        let origin = crate::stream::Origin::Http(base);
        if let Some(streamed) = crate::stream::open(origin).await? {
            return start_streamed(params, streamed, start).await;
        }
    }
    let world = match &params.level {
        Some(url) => fetch_world(url).await?,
        None => generate(&params.world).await?,
    };
    if params.compare {
        return crate::compare::run(
            world,
            params.backend,
            params.views,
            params.methods.as_deref(),
        )
        .await;
    }
    watch_folder_picker();
    progress(None, "");
    let backend = params.backend;
    strata_viewer::web::start(viewer_options(params, world, None), backend)
}

/// The viewer's options from the URL's, over `world` (paged or not).
fn viewer_options(
    params: Params,
    world: World,
    paged: Option<strata_viewer::paged::PagedWorld>,
) -> strata_viewer::Options {
    strata_viewer::Options {
        world,
        method: params.method,
        settings: params.settings,
        size: params.size,
        render_scale: params.scale,
        view: params.view,
        script: None,
        vsync: true,
        adapter: Default::default(),
        render: Default::default(),
        out: "screenshots".into(),
        save: Default::default(),
        physics: false,
        paged,
    }
}

/// The viewer over a streamed store: paged terrain whose pages the pump
/// fetches as the view asks for them.
async fn start_streamed(
    params: Params,
    streamed: crate::stream::Streamed,
    start: f64,
) -> anyhow::Result<()> {
    if params.backend == Backend::WebGl2 {
        bail!(
            "{}: a streamed store is drawn through paged terrain, which needs WebGPU \
             (its page table, atlas pyramids and feedback are storage buffers, which WebGL2 \
             does not have); open it without ?backend=webgl2",
            streamed.origin.label()
        );
    }
    let (world, paged) = streamed_world(
        streamed,
        params.view.as_deref(),
        params.gpu_budget,
        params.pump,
    )
    .await?;
    strata_viewer::web::set_page_info("stream_open_ms", (now_ms() - start).into());
    watch_folder_picker();
    progress(None, "");
    let backend = params.backend;
    strata_viewer::web::start(viewer_options(params, world, Some(paged)), backend)
}

/// A streamed store ready for the viewer: the chunk under `view` (default
/// the first) fetched (the camera stands on it), the pump started, the
/// other views' chunks fetched behind it; paged terrain of `gpu_budget`
/// bytes without reader threads.
pub async fn streamed_world(
    streamed: crate::stream::Streamed,
    view: Option<&str>,
    gpu_budget: u64,
    pump: crate::stream::PumpOptions,
) -> anyhow::Result<(World, strata_viewer::paged::PagedWorld)> {
    use strata_render::paged::PageSource;
    use strata_viewer::paged::{Base, EditedPages, PagedWorld};
    let start = now_ms();
    let crate::stream::Streamed {
        world,
        remote,
        origin,
    } = streamed;
    let chosen = match view {
        Some(name) => world.views.iter().find(|v| v.name == name),
        None => world.views.first(),
    };
    let (w, h) = remote.size();
    let (x, y) = chosen.map_or((w as f32 / 2.0, h as f32 / 2.0), |v| (v.x, v.y));
    crate::stream::prefetch_at(&origin, &remote, x, y, pump.timeout_ms).await?;
    web_sys::console::log_1(
        &format!(
            "strata: streaming {} ({w}x{h}): the first view's chunk in {:.0} ms",
            origin.label(),
            now_ms() - start
        )
        .into(),
    );
    strata_viewer::web::set_page_info("world_size", serde_json::json!([w, h]));
    crate::stream::start_pump(remote.clone(), origin.clone(), pump);
    // The other views' chunks (a view switch places its camera there).
    let mut spots: Vec<(f32, f32)> = world.views.iter().map(|v| (v.x, v.y)).collect();
    if let Some(edit) = &world.edit {
        spots.push((edit.camera.x, edit.camera.y));
    }
    let behind = remote.clone();
    wasm_bindgen_futures::spawn_local(async move {
        for (x, y) in spots {
            if let Err(e) =
                crate::stream::prefetch_at(&origin, &behind, x, y, pump.timeout_ms).await
            {
                web_sys::console::warn_1(&format!("strata: {e:#}").into());
            }
        }
    });
    let pages = EditedPages::new(Base::Remote(remote), world.level.mid_rule)?;
    let options = strata_render::paged::PagedOptions {
        gpu_budget,
        // No threads in the page: the pump's fetches are the reads.
        threads: 0,
        ..Default::default()
    };
    let paged = PagedWorld {
        pages: std::sync::Arc::new(pages),
        options,
    };
    Ok((world, paged))
}

/// `url` ending in `/`.
fn with_slash(url: &str) -> String {
    if url.ends_with('/') {
        url.to_string()
    } else {
        format!("{url}/")
    }
}

/// The built-in world, generated here a band of rows per turn of the
/// browser's loop (about 50 ms each), so the page stays responsive.
async fn generate(params: &GenerateParams) -> anyhow::Result<World> {
    let label = format!(
        "generating the {}x{} world (seed {})",
        params.width, params.height, params.seed
    );
    progress(Some(0.0), &label);
    yield_to_browser().await;
    let start = now_ms();
    let mut generation = Generation::new(params)?;
    let setup_ms = now_ms() - start;
    let mut rows = 16;
    loop {
        let band = now_ms();
        if generation.step(rows) {
            break;
        }
        // Aim at about 50 ms of work between yields.
        let took = (now_ms() - band).max(1.0);
        rows = ((f64::from(rows) * 50.0 / took) as u32).clamp(1, 4096);
        progress(Some(f64::from(generation.progress())), &label);
        set_state(serde_json::json!({
            "phase": "generating",
            "progress": generation.progress(),
        }));
        yield_to_browser().await;
    }
    let world = generation.finish()?;
    let generate_ms = now_ms() - start;
    web_sys::console::log_1(
        &format!("strata: generated {label} in {generate_ms:.0} ms (setup {setup_ms:.0} ms)")
            .into(),
    );
    strata_viewer::web::set_page_info("generate_ms", generate_ms.into());
    strata_viewer::web::set_page_info(
        "world_size",
        serde_json::json!([params.width, params.height]),
    );
    Ok(world)
}

/// GET `url`: its bytes, `None` on 404, an error on anything else.
pub(crate) async fn fetch(url: &str) -> anyhow::Result<Option<Vec<u8>>> {
    let window = web_sys::window().context("no window")?;
    let response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(|e| anyhow::anyhow!("GET {url} failed: {e:?}"))?;
    let response: web_sys::Response = response
        .dyn_into()
        .map_err(|_| anyhow::anyhow!("GET {url}: not a response"))?;
    if response.status() == 404 {
        return Ok(None);
    }
    if !response.ok() {
        bail!(
            "GET {url}: HTTP {} {}",
            response.status(),
            response.status_text()
        );
    }
    let buffer = response
        .array_buffer()
        .map_err(|e| anyhow::anyhow!("GET {url}: {e:?}"))?;
    let buffer = JsFuture::from(buffer)
        .await
        .map_err(|e| anyhow::anyhow!("GET {url}: reading the body failed: {e:?}"))?;
    Ok(Some(js_sys::Uint8Array::new(&buffer).to_vec()))
}

/// Where a world directory's files come from: a URL served over HTTP, or
/// a folder the person picked.
enum Folder {
    Http(String),
    Picked {
        name: String,
        files: Vec<web_sys::File>,
    },
}

impl Folder {
    /// How messages name the folder.
    fn label(&self) -> String {
        match self {
            Folder::Http(base) => base.clone(),
            Folder::Picked { name, .. } => format!("the picked folder `{name}`"),
        }
    }

    /// The file `name` of the folder, `None` when it has none.
    async fn get(&self, name: &str) -> anyhow::Result<Option<Vec<u8>>> {
        match self {
            Folder::Http(base) => fetch(&format!("{base}{name}")).await,
            Folder::Picked { files, .. } => {
                // Top-level files first (a folder's subfolders come along too).
                let depth = |f: &web_sys::File| relative_path(f).matches('/').count();
                let Some(file) = files
                    .iter()
                    .filter(|f| f.name() == name)
                    .min_by_key(|f| depth(f))
                else {
                    return Ok(None);
                };
                let buffer = JsFuture::from(file.array_buffer())
                    .await
                    .map_err(|e| anyhow::anyhow!("reading {name}: {e:?}"))?;
                Ok(Some(js_sys::Uint8Array::new(&buffer).to_vec()))
            }
        }
    }

    async fn required(&self, name: &str) -> anyhow::Result<Vec<u8>> {
        self.get(name).await?.with_context(|| match self {
            Folder::Http(base) if name == strata_level::io::WORLD_INI => format!(
                "GET {base}{name}: 404 Not Found: no Strata store (zarr.json) and no world \
                 directory (world.ini) at {base}"
            ),
            Folder::Http(base) => {
                format!("GET {base}{name}: 404 Not Found (a world directory needs this file)")
            }
            Folder::Picked { name: folder, .. } => {
                format!("the picked folder `{folder}` has no {name} (a world directory needs it)")
            }
        })
    }
}

/// A picked file's path under the picked folder's parent (`fostral/world.ini`;
/// web-sys does not bind `webkitRelativePath`).
fn relative_path(file: &web_sys::File) -> String {
    js_sys::Reflect::get(file, &"webkitRelativePath".into())
        .ok()
        .and_then(|v| v.as_string())
        .unwrap_or_default()
}

/// A world directory served over HTTP (`world.ini`, the map, the palette,
/// optionally `.vpr`, `views.txt`, `edit.txt`), through the native readers.
async fn fetch_world(url: &str) -> anyhow::Result<World> {
    load_world(&Folder::Http(with_slash(url))).await
}

/// A world folder from the page's file picker.
pub async fn picked_world(files: Vec<web_sys::File>) -> anyhow::Result<World> {
    let name = picked_name(&files);
    let world = load_world(&Folder::Picked { name, files }).await?;
    progress(None, "");
    Ok(world)
}

/// The picked folder's name (its files' first path component).
fn picked_name(files: &[web_sys::File]) -> String {
    files
        .first()
        .map(relative_path)
        .and_then(|p| p.split('/').next().map(str::to_string))
        .filter(|n| !n.is_empty())
        .unwrap_or_else(|| "world".into())
}

/// A picked folder that is a Strata store, ready to stream from its files
/// (`None`: no zarr.json at its top; maybe a world directory).
async fn picked_store(
    files: &[web_sys::File],
) -> anyhow::Result<Option<(World, strata_viewer::paged::PagedWorld)>> {
    let name = picked_name(files);
    // Paths under the picked folder (`heights/c/3/1`).
    let by_path: std::collections::HashMap<String, web_sys::File> = files
        .iter()
        .filter_map(|f| {
            let path = relative_path(f);
            let (_, under) = path.split_once('/')?;
            Some((under.to_string(), f.clone()))
        })
        .collect();
    if !by_path.contains_key("zarr.json") {
        return Ok(None);
    }
    let origin = crate::stream::Origin::Picked {
        name,
        files: std::rc::Rc::new(by_path),
    };
    progress(Some(0.0), &format!("opening {}", origin.label()));
    let Some(streamed) = crate::stream::open(origin).await? else {
        return Ok(None);
    };
    streamed_world(
        streamed,
        None,
        DEFAULT_GPU_BUDGET_MIB << 20,
        crate::stream::PumpOptions::default(),
    )
    .await
    .map(Some)
}

async fn load_world(folder: &Folder) -> anyhow::Result<World> {
    use std::path::Path;
    use strata_level::config::WorldConfig;
    use strata_level::{MidRule, io};
    let label = folder.label();
    let dir = Path::new(label.trim_end_matches('/'));
    progress(Some(0.0), &format!("loading the world at {label}"));
    let ini = folder.required(io::WORLD_INI).await?;
    let config = WorldConfig::parse(&String::from_utf8_lossy(&ini), &dir.join(io::WORLD_INI))?;
    let map_path = io::map_path(dir, &config);
    let map_name = map_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    progress(Some(0.1), &format!("loading {map_name} from {label}"));
    let map = folder.required(&map_name).await?;
    let palette = folder.required(&config.palette_file).await?;
    let vpr = folder.get(&format!("{}.vpr", config.file_name)).await?;
    let views = folder.get(io::VIEWS_TXT).await?;
    let edit = folder.get(io::EDIT_TXT).await?;
    progress(Some(0.5), &format!("decoding {map_name} from {label}"));
    yield_to_browser().await;
    let level = io::decode_map(&map, &config, MidRule::Original, &map_path)?;
    drop(map);
    let name = match folder {
        Folder::Picked { name, .. } => name.clone(),
        Folder::Http(_) => dir
            .file_name()
            .map_or_else(|| "world".into(), |n| n.to_string_lossy().into_owned()),
    };
    Ok(io::world_from_parts(
        name,
        dir,
        config,
        level,
        io::WorldFiles {
            palette: &palette,
            vpr: vpr.as_deref(),
            views: views.as_deref(),
            edit: edit.as_deref(),
        },
    )?)
}

/// The page's folder picker: a picked world folder replaces the world the
/// viewer shows; a bad one gets the same clear error as natively.
pub fn watch_folder_picker() {
    let Some(input) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id("strata-open"))
        .and_then(|e| e.dyn_into::<web_sys::HtmlInputElement>().ok())
    else {
        return;
    };
    let picker = input.clone();
    let on_change = wasm_bindgen::closure::Closure::<dyn FnMut()>::new(move || {
        let Some(list) = picker.files() else { return };
        let files: Vec<web_sys::File> = (0..list.length()).filter_map(|i| list.get(i)).collect();
        if files.is_empty() {
            return;
        }
        strata_viewer::web::clear_error();
        wasm_bindgen_futures::spawn_local(async move {
            // A store (a zarr.json at its top) is streamed from the files.
            match picked_store(&files).await {
                Ok(Some((world, paged))) => {
                    progress(None, "");
                    web_sys::console::log_1(&format!("strata: streaming {}", world.name).into());
                    strata_viewer::web::open_paged_world(world, paged);
                    return;
                }
                Ok(None) => {}
                Err(error) => {
                    progress(None, "");
                    strata_viewer::web::show_error(&format!("{error:#}"));
                    return;
                }
            }
            match picked_world(files).await {
                Ok(world) => {
                    web_sys::console::log_1(&format!("strata: opened {}", world.name).into());
                    strata_viewer::web::open_world(world);
                }
                Err(error) => {
                    progress(None, "");
                    strata_viewer::web::show_error(&format!("{error:#}"));
                }
            }
        });
    });
    input.set_onchange(Some(on_change.as_ref().unchecked_ref()));
    // The page lives as long as the picker: keep the handler.
    on_change.forget();
}
