//! Checking a comparison's inputs before any GPU work: the output directory,
//! the size, the method list, the views. Every error here names what was wrong.

use anyhow::{Context, bail};
use std::path::Path;
use strata_render::MethodEntry;
use strata_render::methods::METHODS;

/// `WxH`, both positive and at most 16384.
pub fn parse_size(text: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("size `{text}` must be WxH, e.g. 1280x800"))?;
    let parse = |s: &str| -> anyhow::Result<u32> {
        let v: u32 = s
            .trim()
            .parse()
            .with_context(|| format!("size `{text}`: `{s}` is not a whole number"))?;
        if v == 0 || v > 16384 {
            bail!("size `{text}`: {v} must be in 1..=16384");
        }
        Ok(v)
    };
    Ok((parse(w)?, parse(h)?))
}

/// A method as named on the command line: `name` or `name:setting`. The
/// method is its entry in `strata_render::methods::METHODS`; the label
/// (`ray:64`) only names the column in results and reports.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MethodChoice {
    pub method: &'static MethodEntry,
    pub setting: Option<String>,
}

impl MethodChoice {
    /// `method` at its default setting.
    pub fn plain(method: &'static MethodEntry) -> Self {
        MethodChoice {
            method,
            setting: None,
        }
    }

    /// The method's name (`ray`).
    pub fn name(&self) -> &'static str {
        self.method.name
    }

    /// The label used in results and reports.
    pub fn label(&self) -> String {
        match &self.setting {
            Some(s) => format!("{}:{s}", self.method.name),
            None => self.method.name.to_string(),
        }
    }
}

/// Every method of `METHODS` at its default setting.
pub fn every_method() -> Vec<MethodChoice> {
    METHODS.iter().map(MethodChoice::plain).collect()
}

/// Parse `a,b:setting,c` against the methods `known` (a part of `METHODS`,
/// usually all of it). A setting may hold commas (`voxel:4,8,2/100`,
/// `scattered:4,4,4`): a comma-separated piece that starts with a digit,
/// `(`, `.` or `-` continues the previous setting. Duplicate labels and
/// unknown names are errors (listing the known ones).
pub fn parse_methods(
    list: &str,
    known: &'static [MethodEntry],
) -> anyhow::Result<Vec<MethodChoice>> {
    let names = || known.iter().map(|m| m.name).collect::<Vec<_>>().join(", ");
    let mut out: Vec<MethodChoice> = Vec::new();
    for piece in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let continues = piece.starts_with(|c: char| c.is_ascii_digit() || "(.-".contains(c));
        if continues {
            match out.last_mut() {
                Some(MethodChoice {
                    setting: Some(s), ..
                }) => {
                    s.push(',');
                    s.push_str(piece);
                    continue;
                }
                _ => bail!(
                    "`{piece}` in the method list is not a method name (known: {})",
                    names()
                ),
            }
        }
        let (name, setting) = match piece.split_once(':') {
            Some((n, s)) => (n.trim(), Some(s.trim().to_string())),
            None => (piece, None),
        };
        let Some(method) = known.iter().find(|m| m.name == name) else {
            bail!("unknown method `{name}` (known: {})", names());
        };
        out.push(MethodChoice { method, setting });
    }
    for (i, c) in out.iter().enumerate() {
        if out[..i].iter().any(|o| o.label() == c.label()) {
            bail!("method `{}` is listed twice", c.label());
        }
    }
    if out.is_empty() {
        bail!("the method list `{list}` names no method");
    }
    Ok(out)
}

/// Create `dir` (and `dir/cells`) and prove it writable by writing and
/// removing a probe file.
pub fn prepare_out_dir(dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir.join("cells"))
        .with_context(|| format!("cannot create the output directory {}", dir.display()))?;
    let probe = dir.join(".strata-write-probe");
    std::fs::write(&probe, b"probe")
        .with_context(|| format!("the output directory {} is not writable", dir.display()))?;
    std::fs::remove_file(&probe).with_context(|| format!("cannot remove {}", probe.display()))?;
    Ok(())
}

/// View names become file names: refuse duplicates and path characters.
pub fn check_view_names(views: &[strata_level::ViewSpec]) -> anyhow::Result<()> {
    if views.is_empty() {
        bail!("no views to render (the level has none and no --views file was given)");
    }
    for (i, v) in views.iter().enumerate() {
        if v.name.is_empty()
            || !v
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
            || v.name.starts_with('.')
        {
            bail!(
                "view name `{}` must be letters, digits, `-`, `_` or `.`",
                v.name
            );
        }
        if views[..i].iter().any(|o| o.name == v.name) {
            bail!("view `{}` appears twice", v.name);
        }
    }
    Ok(())
}

/// File-name-safe form of a method label (`voxel:4,8,2/100` -> `voxel-4-8-2-100`).
pub fn file_part(label: &str) -> String {
    let mut s: String = label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect();
    while s.contains("--") {
        s = s.replace("--", "-");
    }
    s.trim_matches('-').to_string()
}

/// The revision this binary was built from (`git describe --always --tags`,
/// `-dirty` when the sources differed from the commit, `unknown` outside
/// git), baked in at build time by `build.rs`: where the binary runs, and
/// what that directory holds, change nothing.
pub const SOURCE_REVISION: &str = env!("STRATA_BUILD_REVISION");

/// [`SOURCE_REVISION`] as a `String`, for results and reports.
pub fn source_revision() -> String {
    SOURCE_REVISION.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("1280x800").unwrap(), (1280, 800));
        assert_eq!(parse_size("320X200").unwrap(), (320, 200));
        for bad in ["1280", "0x800", "ax800", "1280x", "99999x10"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn methods() {
        // `ray` and `ray-compute`.
        let known = &METHODS[..2];
        let m = parse_methods("ray, ray-compute:4,8,2/100,ray:64", known).unwrap();
        assert_eq!(m.len(), 3);
        assert_eq!(m[1].label(), "ray-compute:4,8,2/100");
        assert_eq!(m[1].method.name, "ray-compute");
        assert_eq!(m[2].setting.as_deref(), Some("64"));
        assert_eq!(m[2].method, &METHODS[0]);
        assert!(parse_methods("8,ray", known).is_err());
        let err = parse_methods("ray,mesh", known).unwrap_err().to_string();
        assert!(
            err.contains("unknown method `mesh`") && err.contains("ray, ray-compute"),
            "{err}"
        );
        assert!(parse_methods("ray,ray", known).is_err());
        assert!(parse_methods(" , ", known).is_err());
        assert_eq!(
            parse_methods("mesh:0.75", METHODS).unwrap()[0].label(),
            "mesh:0.75"
        );
    }

    #[test]
    fn out_dir_must_be_writable() {
        let dir = std::env::temp_dir().join(format!("strata-plan-{}", std::process::id()));
        prepare_out_dir(&dir).unwrap();
        assert!(dir.join("cells").is_dir());
        // A path under a regular file cannot be created.
        let file = dir.join("file");
        std::fs::write(&file, b"x").unwrap();
        assert!(prepare_out_dir(&file.join("sub")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn file_parts() {
        assert_eq!(file_part("voxel:4,8,2/100"), "voxel-4-8-2-100");
        assert_eq!(file_part("mesh:q=0.5"), "mesh-q-0.5");
    }
}
