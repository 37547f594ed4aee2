//! `world.ini`: the world's configuration.
//!
//! Parsing keeps every section and key (also the ones we do not interpret) in
//! [`WorldConfig::ini`], so writing a parsed file preserves them; values we
//! do interpret are written back in their original text when unchanged.

use crate::error::LevelError;
use std::path::Path;

/// One `[Section]` of an ini file: its `Key=Value` lines in file order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct IniSection {
    pub name: String,
    pub entries: Vec<(String, String)>,
}

/// An ini file as sections of key/value pairs, in file order. Comments and
/// blank lines are not kept.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Ini {
    pub sections: Vec<IniSection>,
}

impl Ini {
    /// Parse ini text. Lines before the first section go to a section named "".
    /// `;` and `#` start comment lines. A line that is neither a section, a
    /// key, a comment nor blank is an error (reported with its line number).
    pub fn parse(text: &str) -> Result<Self, (usize, String)> {
        let mut ini = Ini::default();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.is_empty() || line.starts_with(';') || line.starts_with('#') {
                continue;
            }
            if let Some(rest) = line.strip_prefix('[') {
                let name = rest
                    .strip_suffix(']')
                    .ok_or((i + 1, format!("section header `{line}` lacks `]`")))?;
                ini.sections.push(IniSection {
                    name: name.trim().to_string(),
                    entries: Vec::new(),
                });
                continue;
            }
            let (key, value) = line
                .split_once('=')
                .ok_or((i + 1, format!("`{line}` is not `Key=Value`")))?;
            if ini.sections.is_empty() {
                ini.sections.push(IniSection::default());
            }
            if let Some(section) = ini.sections.last_mut() {
                section
                    .entries
                    .push((key.trim().to_string(), value.trim().to_string()));
            }
        }
        Ok(ini)
    }

    /// The value of `key` in `section` (first occurrence).
    pub fn get(&self, section: &str, key: &str) -> Option<&str> {
        self.sections
            .iter()
            .filter(|s| s.name == section)
            .flat_map(|s| s.entries.iter())
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// Set `key` in `section`, in place when present, else appended
    /// (creating the section at the end when needed).
    pub fn set(&mut self, section: &str, key: &str, value: String) {
        if let Some(entry) = self
            .sections
            .iter_mut()
            .filter(|s| s.name == section)
            .flat_map(|s| s.entries.iter_mut())
            .find(|(k, _)| k == key)
        {
            entry.1 = value;
            return;
        }
        match self.sections.iter_mut().find(|s| s.name == section) {
            Some(s) => s.entries.push((key.to_string(), value)),
            None => self.sections.push(IniSection {
                name: section.to_string(),
                entries: vec![(key.to_string(), value)],
            }),
        }
    }

    /// The file text: `[Section]` then `Key=Value` lines, a blank line between sections.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for (i, section) in self.sections.iter().enumerate() {
            if i > 0 {
                out.push('\n');
            }
            if !(section.name.is_empty() && i == 0) {
                out.push_str(&format!("[{}]\n", section.name));
            }
            for (k, v) in &section.entries {
                out.push_str(&format!("{k}={v}\n"));
            }
        }
        out
    }
}

const GLOBAL: &str = "Global Parameters";
const STORAGE: &str = "Storage";
const RENDERING: &str = "Rendering Parameters";

/// The parts of `world.ini` the renderer and the file formats need.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorldConfig {
    /// Width = 2^`Map Power X`.
    pub map_power_x: u32,
    /// Height = 2^`Map Power Y`.
    pub map_power_y: u32,
    /// `[Storage] Compressed Format Using=1`: the map is `.vmc`, else `.vmp`.
    pub compressed: bool,
    /// `[Storage] File Name`, without extension.
    pub file_name: String,
    /// `[Storage] Palette File`.
    pub palette_file: String,
    /// First palette index of each terrain type's colour range.
    pub begin_colors: [u8; 8],
    /// Last palette index of each terrain type's colour range.
    pub end_colors: [u8; 8],
    /// The whole file as parsed (every section and key, also those not
    /// interpreted above), so writing preserves it. Empty for a new world:
    /// writing then emits only the keys above plus Fostral's defaults.
    pub ini: Ini,
}

impl Default for WorldConfig {
    /// Fostral's size, storage and colour ranges, under the file name `output`.
    fn default() -> Self {
        WorldConfig {
            map_power_x: 11,
            map_power_y: 14,
            compressed: true,
            file_name: "output".into(),
            palette_file: "harmony.pal".into(),
            begin_colors: [1, 32, 64, 72, 88, 104, 112, 120],
            end_colors: [31, 63, 71, 87, 103, 111, 119, 127],
            ini: Ini::default(),
        }
    }
}

/// Map powers above this are refused: 2^15 rows of 2^15 texels is already
/// 2 GiB of planes, far beyond any Vangers world.
const MAX_POWER: u32 = 15;

impl WorldConfig {
    pub fn width(&self) -> u32 {
        1 << self.map_power_x
    }
    pub fn height(&self) -> u32 {
        1 << self.map_power_y
    }

    /// `[Global Parameters] Section Size Power` (rows per `.vpr` water
    /// section = 2^this); 7 when absent, as in Fostral.
    pub fn section_size_power(&self) -> u32 {
        self.ini
            .get(GLOBAL, "Section Size Power")
            .and_then(|v| v.parse().ok())
            .filter(|p| *p <= MAX_POWER)
            .unwrap_or(7)
    }

    /// Parse `world.ini` text; `path` only names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, LevelError> {
        let ini = Ini::parse(text)
            .map_err(|(line, msg)| LevelError::format(path, format!("line {line}: {msg}")))?;
        let err = |section: &str, key: &str, msg: String| LevelError::Ini {
            path: path.to_path_buf(),
            section: section.to_string(),
            key: key.to_string(),
            msg,
        };
        let get = |section: &str, key: &str| {
            ini.get(section, key)
                .ok_or_else(|| err(section, key, "missing".into()))
        };
        let power = |key: &str| -> Result<u32, LevelError> {
            let v = get(GLOBAL, key)?;
            let p: u32 = v
                .parse()
                .map_err(|_| err(GLOBAL, key, format!("`{v}` is not a whole number")))?;
            if !(1..=MAX_POWER).contains(&p) {
                return Err(err(GLOBAL, key, format!("{p} is outside 1..={MAX_POWER}")));
            }
            Ok(p)
        };
        let colors = |key: &str| -> Result<[u8; 8], LevelError> {
            let v = get(RENDERING, key)?;
            let numbers: Vec<&str> = v.split_whitespace().collect();
            if numbers.len() != 8 {
                return Err(err(
                    RENDERING,
                    key,
                    format!(
                        "{} values, expected 8 (one per terrain type)",
                        numbers.len()
                    ),
                ));
            }
            let mut out = [0u8; 8];
            for (o, n) in out.iter_mut().zip(&numbers) {
                *o = n.parse().map_err(|_| {
                    err(
                        RENDERING,
                        key,
                        format!("`{n}` is not a palette index 0..255"),
                    )
                })?;
            }
            Ok(out)
        };
        let compressed = match get(STORAGE, "Compressed Format Using")? {
            "0" => false,
            "1" => true,
            other => {
                return Err(err(
                    STORAGE,
                    "Compressed Format Using",
                    format!("`{other}` is neither 0 nor 1"),
                ));
            }
        };
        let name = |key: &str| -> Result<String, LevelError> {
            let v = get(STORAGE, key)?;
            // The name is joined to the world directory: refuse anything
            // that could step outside it.
            if v.is_empty() || v.contains(['/', '\\']) || v == ".." {
                return Err(err(STORAGE, key, format!("`{v}` is not a plain file name")));
            }
            Ok(v.to_string())
        };
        let config = WorldConfig {
            map_power_x: power("Map Power X")?,
            map_power_y: power("Map Power Y")?,
            compressed,
            file_name: name("File Name")?,
            palette_file: name("Palette File")?,
            begin_colors: colors("Begin Colors")?,
            end_colors: colors("End Colors")?,
            ini: Ini::default(),
        };
        Ok(WorldConfig { ini, ..config })
    }

    /// Read and parse a `world.ini` file.
    pub fn read(path: &Path) -> Result<Self, LevelError> {
        let bytes = crate::error::read_file(path)?;
        let text = String::from_utf8_lossy(&bytes);
        Self::parse(&text, path)
    }

    /// The file text. Keys of [`Self::ini`] are preserved; interpreted keys
    /// keep their original text when their value is unchanged.
    pub fn to_ini_text(&self) -> String {
        let mut ini = if self.ini.sections.is_empty() {
            fostral_like_ini()
        } else {
            self.ini.clone()
        };
        let mut set = |section: &str, key: &str, value: String, same: &dyn Fn(&str) -> bool| {
            if !ini.get(section, key).is_some_and(same) {
                ini.set(section, key, value);
            }
        };
        let num = |n: u32| move |v: &str| v.parse::<u32>() == Ok(n);
        set(
            GLOBAL,
            "Map Power X",
            self.map_power_x.to_string(),
            &num(self.map_power_x),
        );
        set(
            GLOBAL,
            "Map Power Y",
            self.map_power_y.to_string(),
            &num(self.map_power_y),
        );
        let c = u32::from(self.compressed);
        set(STORAGE, "Compressed Format Using", c.to_string(), &num(c));
        let f = self.file_name.clone();
        set(STORAGE, "File Name", f.clone(), &|v: &str| v == f);
        let p = self.palette_file.clone();
        set(STORAGE, "Palette File", p.clone(), &|v: &str| v == p);
        for (key, colors) in [
            ("Begin Colors", self.begin_colors),
            ("End Colors", self.end_colors),
        ] {
            let text = colors.map(|c| c.to_string()).join(" ");
            let same = move |v: &str| {
                let parsed: Vec<Option<u8>> =
                    v.split_whitespace().map(|n| n.parse().ok()).collect();
                parsed == colors.map(Some).to_vec()
            };
            set(RENDERING, key, text, &same);
        }
        ini.to_text()
    }

    /// Write `world.ini`.
    pub fn write(&self, path: &Path) -> Result<(), LevelError> {
        crate::error::write_file(path, self.to_ini_text().as_bytes())
    }
}

/// The keys the original game reads besides those [`WorldConfig`]
/// interprets, with Fostral's values: a world we write from scratch carries
/// them so the game's own loader finds them.
fn fostral_like_ini() -> Ini {
    let text = "[Global Parameters]\nMap Power X=11\nMap Power Y=14\nGeoNet Power=5\n\
        Section Size Power=7\nMinimal Square Power=4\n\
        [Storage]\nVersion=1.4\nCompressed Format Using=1\nFile Name=output\nPalette File=harmony.pal\n\
        [Rendering Parameters]\nShadow Offsets=10 12 4 9 6 4 4 4\nHeight Shifts=2 4 8 8 5 6 6 6\n\
        Begin Colors=1 32 64 72 88 104 112 120\nEnd Colors=31 63 71 87 103 111 119 127\n";
    Ini::parse(text).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fostral_path() -> std::path::PathBuf {
        crate::error::fostral_file("world.ini")
    }

    #[test]
    fn fostral_world_ini_parses() {
        let config = WorldConfig::read(&fostral_path()).unwrap();
        assert_eq!((config.width(), config.height()), (2048, 16384));
        assert!(config.compressed);
        assert_eq!(config.file_name, "output");
        assert_eq!(config.palette_file, "harmony.pal");
        assert_eq!(config.begin_colors, [1, 32, 64, 72, 88, 104, 112, 120]);
        assert_eq!(config.end_colors, [31, 63, 71, 87, 103, 111, 119, 127]);
        assert_eq!(config.section_size_power(), 7);
        assert_eq!(
            config.ini.get("Dynamic Palette", "Speeds"),
            Some("128 128 256")
        );
    }

    #[test]
    fn writing_preserves_unknown_keys_and_changes() {
        let mut config = WorldConfig::read(&fostral_path()).unwrap();
        let text = config.to_ini_text();
        // Unchanged values keep their original spacing.
        assert!(
            text.contains("Begin Colors=1 32 64 72  88 104 112 120"),
            "{text}"
        );
        assert!(text.contains("[Creation Parameters]") && text.contains("Mesh Value=256"));
        assert_eq!(WorldConfig::parse(&text, Path::new("x")).unwrap(), config);
        config.map_power_y = 10;
        config.compressed = false;
        config.end_colors[7] = 200;
        let again = WorldConfig::parse(&config.to_ini_text(), Path::new("x")).unwrap();
        assert_eq!(
            (again.height(), again.compressed, again.end_colors[7]),
            (1024, false, 200)
        );
        assert_eq!(again.ini.get("Dynamic Palette", "Terrains"), Some("5 4 6"));
    }

    #[test]
    fn new_config_round_trips() {
        let config = WorldConfig {
            file_name: "mine".into(),
            ..WorldConfig::default()
        };
        let parsed = WorldConfig::parse(&config.to_ini_text(), Path::new("x")).unwrap();
        assert_eq!(parsed.file_name, "mine");
        assert_eq!(
            parsed.ini.get("Global Parameters", "GeoNet Power"),
            Some("5")
        );
        assert_eq!(
            WorldConfig {
                ini: Ini::default(),
                ..parsed
            },
            config
        );
    }

    #[test]
    fn bad_values_name_section_and_key() {
        let good = WorldConfig::default().to_ini_text();
        let cases = [
            (
                "Map Power X=11\n",
                "",
                "[Global Parameters] Map Power X: missing",
            ),
            (
                "Map Power X=11",
                "Map Power X=eleven",
                "[Global Parameters] Map Power X: `eleven`",
            ),
            (
                "Map Power Y=14",
                "Map Power Y=40",
                "[Global Parameters] Map Power Y: 40 is outside",
            ),
            (
                "Compressed Format Using=1",
                "Compressed Format Using=yes",
                "[Storage] Compressed Format Using",
            ),
            (
                "Begin Colors=1 32 64 72 88 104 112 120",
                "Begin Colors=1 32",
                "[Rendering Parameters] Begin Colors: 2 values",
            ),
            (
                "End Colors=31 63 71 87 103 111 119 127",
                "End Colors=31 63 71 87 103 111 119 300",
                "End Colors: `300`",
            ),
            ("File Name=output", "File Name=../x", "[Storage] File Name"),
            ("[Storage]", "[Storage", "line"),
        ];
        for (from, to, expected) in cases {
            assert!(good.contains(from), "{from}");
            let bad = good.replace(from, to);
            let err = WorldConfig::parse(&bad, Path::new("w/world.ini"))
                .unwrap_err()
                .to_string();
            assert!(err.starts_with("w/world.ini: "), "{err}");
            assert!(err.contains(expected), "{err} lacks {expected}");
        }
    }
}
