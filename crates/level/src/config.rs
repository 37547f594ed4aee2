//! `world.ini`: the world's configuration.
//!
//! [`Ini`] keeps the file as written: every line (comments, blank lines,
//! spacing, line endings) is kept, and setting a value rewrites only its own
//! line, so a file read and written back unchanged is byte-identical, and
//! an edited one differs only in the edited lines. A file that is not UTF-8
//! (the game's own files are from a DOS/Windows era) is read as Latin-1 and
//! written back in it, byte for byte.

use crate::error::LevelError;
use std::path::Path;

/// One line of an ini file, kept as written (its terminator included).
#[derive(Clone, Debug, PartialEq, Eq)]
struct IniLine {
    text: String,
    /// `Key=Value`, trimmed; `None` for a comment or blank line.
    entry: Option<(String, String)>,
}

/// One `[Section]` of an ini file: its header line and the lines after it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct IniSection {
    name: String,
    /// The header line as written; `None` for the lines before the first header.
    header: Option<String>,
    lines: Vec<IniLine>,
}

/// An ini file, line for line. `;` and `#` start comment lines.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Ini {
    sections: Vec<IniSection>,
    /// The file was not UTF-8 and was read as Latin-1 (written back the same way).
    latin1: bool,
}

/// A line's terminator: `\r\n`, `\n`, or none (the file's last line).
fn line_ending(line: &str) -> &str {
    if line.ends_with("\r\n") {
        "\r\n"
    } else if line.ends_with('\n') {
        "\n"
    } else {
        ""
    }
}

impl Ini {
    /// Parse ini text. Lines before the first section go to a section named "".
    /// A line that is neither a section, a key, a comment nor blank is an
    /// error (reported with its line number).
    pub fn parse(text: &str) -> Result<Self, (usize, String)> {
        let mut ini = Ini::default();
        for (i, raw) in text.split_inclusive('\n').enumerate() {
            let line = raw.trim();
            let mut entry = None;
            if let Some(rest) = line.strip_prefix('[') {
                let name = rest
                    .strip_suffix(']')
                    .ok_or((i + 1, format!("section header `{line}` lacks `]`")))?;
                ini.sections.push(IniSection {
                    name: name.trim().to_string(),
                    header: Some(raw.to_string()),
                    lines: Vec::new(),
                });
                continue;
            }
            if !(line.is_empty() || line.starts_with(';') || line.starts_with('#')) {
                let (key, value) = line
                    .split_once('=')
                    .ok_or((i + 1, format!("`{line}` is not `Key=Value`")))?;
                entry = Some((key.trim().to_string(), value.trim().to_string()));
            }
            if ini.sections.is_empty() {
                ini.sections.push(IniSection::default());
            }
            if let Some(section) = ini.sections.last_mut() {
                section.lines.push(IniLine {
                    text: raw.to_string(),
                    entry,
                });
            }
        }
        Ok(ini)
    }

    /// Parse a file's bytes: UTF-8, else Latin-1 (so no byte is lost).
    pub fn parse_bytes(bytes: &[u8]) -> Result<Self, (usize, String)> {
        match std::str::from_utf8(bytes) {
            Ok(text) => Self::parse(text),
            Err(_) => {
                let text: String = bytes.iter().map(|&b| char::from(b)).collect();
                Ok(Ini {
                    latin1: true,
                    ..Self::parse(&text)?
                })
            }
        }
    }

    /// The value of `key` in `section` (first occurrence).
    pub fn get(&self, section: &str, key: &str) -> Option<&str> {
        self.sections
            .iter()
            .filter(|s| s.name == section)
            .flat_map(|s| s.lines.iter())
            .filter_map(|l| l.entry.as_ref())
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The line ending most of the file uses (`\n` for an empty file).
    fn newline(&self) -> &'static str {
        let crlf = self
            .sections
            .iter()
            .flat_map(|s| s.header.iter().chain(s.lines.iter().map(|l| &l.text)))
            .find(|t| t.ends_with('\n'))
            .is_some_and(|t| t.ends_with("\r\n"));
        if crlf { "\r\n" } else { "\n" }
    }

    /// Set `key` in `section`: its line rewritten in place when present
    /// (the key as written and the line ending kept), else a line appended
    /// after the section's last key (creating the section at the end when
    /// needed). No other line changes.
    pub fn set(&mut self, section: &str, key: &str, value: String) {
        let newline = self.newline();
        if let Some(line) = self
            .sections
            .iter_mut()
            .filter(|s| s.name == section)
            .flat_map(|s| s.lines.iter_mut())
            .find(|l| l.entry.as_ref().is_some_and(|(k, _)| k == key))
        {
            let key_as_written = line.text.split_once('=').map_or(key, |(k, _)| k);
            line.text = format!("{key_as_written}={value}{}", line_ending(&line.text));
            line.entry = Some((key.to_string(), value));
            return;
        }
        let new_line = IniLine {
            text: format!("{key}={value}{newline}"),
            entry: Some((key.to_string(), value)),
        };
        // Only the file's last line may lack a terminator; the line before
        // the new one gets one so that the new line stands on its own.
        let end_line = |text: Option<&mut String>| {
            if let Some(text) = text
                && !text.ends_with('\n')
            {
                text.push_str(newline);
            }
        };
        if let Some(section) = self.sections.iter_mut().find(|s| s.name == section) {
            let at = section
                .lines
                .iter()
                .rposition(|l| l.entry.is_some())
                .map_or(0, |p| p + 1);
            let before = match at {
                0 => section.header.as_mut(),
                _ => Some(&mut section.lines[at - 1].text),
            };
            end_line(before);
            section.lines.insert(at, new_line);
            return;
        }
        let last = self.sections.last_mut();
        let ends_blank = last
            .as_ref()
            .is_none_or(|s| s.lines.last().is_some_and(|l| l.text.trim().is_empty()));
        if let Some(s) = last {
            end_line(
                s.lines
                    .last_mut()
                    .map(|l| &mut l.text)
                    .or(s.header.as_mut()),
            );
            if !ends_blank {
                s.lines.push(IniLine {
                    text: newline.to_string(),
                    entry: None,
                });
            }
        }
        self.sections.push(IniSection {
            name: section.to_string(),
            header: Some(format!("[{section}]{newline}")),
            lines: vec![new_line],
        });
    }

    /// The file text, line for line as read, with the lines [`Self::set`] changed.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for section in &self.sections {
            if let Some(header) = &section.header {
                out.push_str(header);
            }
            for line in &section.lines {
                out.push_str(&line.text);
            }
        }
        out
    }

    /// The file bytes: the text in the encoding it was read in.
    pub fn to_bytes(&self) -> Vec<u8> {
        let text = self.to_text();
        if self.latin1 {
            // Every char came from one byte, or is ASCII that `set` wrote.
            text.chars()
                .map(|c| u8::try_from(c).unwrap_or(b'?'))
                .collect()
        } else {
            text.into_bytes()
        }
    }
}

const GLOBAL: &str = "Global Parameters";
const STORAGE: &str = "Storage";
const RENDERING: &str = "Rendering Parameters";
const SECTION_SIZE_POWER: &str = "Section Size Power";
const GEONET_POWER: &str = "GeoNet Power";

/// A `[Global Parameters]` power that may be absent.
fn optional_power(ini: &Ini, key: &str) -> Option<u32> {
    ini.get(GLOBAL, key)?.parse().ok()
}

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

/// Map powers a Strata store may declare (it is read a chunk at a time, so
/// its size is not bounded by memory): 65536 x 65536 texels.
pub const MAX_STORE_POWER: u32 = 16;

impl WorldConfig {
    /// Map width in texels, `2^Map Power X`.
    pub fn width(&self) -> u32 {
        1 << self.map_power_x
    }
    /// Map height in texels, `2^Map Power Y`.
    pub fn height(&self) -> u32 {
        1 << self.map_power_y
    }

    /// `[Global Parameters] Section Size Power` (rows per `.vpr` water
    /// section = 2^this). When absent: 7 as in Fostral, but at most `Map
    /// Power Y`, so that a small map still has one section. [`Self::parse`]
    /// has checked a present value.
    pub fn section_size_power(&self) -> u32 {
        optional_power(&self.ini, SECTION_SIZE_POWER).unwrap_or(7.min(self.map_power_y))
    }

    /// `[Global Parameters] GeoNet Power` (the original generator's net,
    /// which sizes the `.vpr`); 5 when absent, as in Fostral.
    pub fn geo_net_power(&self) -> u32 {
        optional_power(&self.ini, GEONET_POWER).unwrap_or(5)
    }

    /// Parse `world.ini` text; `path` only names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, LevelError> {
        let ini = Ini::parse(text)
            .map_err(|(line, msg)| LevelError::format(path, format!("line {line}: {msg}")))?;
        Self::from_ini(ini, path)
    }

    /// Parse `world.ini` bytes (UTF-8, else Latin-1, kept for write-back).
    pub fn parse_bytes(bytes: &[u8], path: &Path) -> Result<Self, LevelError> {
        let ini = Ini::parse_bytes(bytes)
            .map_err(|(line, msg)| LevelError::format(path, format!("line {line}: {msg}")))?;
        Self::from_ini(ini, path)
    }

    /// [`WorldConfig::parse_bytes`] for a Strata store's `world.ini`, whose
    /// map powers may go up to [`MAX_STORE_POWER`] (a Vangers world's stop
    /// at 15: it is loaded whole).
    pub fn parse_store_bytes(bytes: &[u8], path: &Path) -> Result<Self, LevelError> {
        let ini = Ini::parse_bytes(bytes)
            .map_err(|(line, msg)| LevelError::format(path, format!("line {line}: {msg}")))?;
        Self::from_ini_max(ini, path, MAX_STORE_POWER)
    }

    fn from_ini(ini: Ini, path: &Path) -> Result<Self, LevelError> {
        Self::from_ini_max(ini, path, MAX_POWER)
    }

    fn from_ini_max(ini: Ini, path: &Path, max_power: u32) -> Result<Self, LevelError> {
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
            if !(1..=max_power).contains(&p) {
                return Err(err(GLOBAL, key, format!("{p} is outside 1..={max_power}")));
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
        // Optional powers the `.vpr` layout depends on: checked here so the
        // accessors need not fail.
        for key in [SECTION_SIZE_POWER, GEONET_POWER] {
            if let Some(v) = ini.get(GLOBAL, key) {
                match v.parse::<u32>() {
                    Ok(p) if p <= MAX_POWER => {}
                    Ok(p) => {
                        return Err(err(GLOBAL, key, format!("{p} is outside 0..={MAX_POWER}")));
                    }
                    Err(_) => {
                        return Err(err(GLOBAL, key, format!("`{v}` is not a whole number")));
                    }
                }
            }
        }
        Ok(WorldConfig { ini, ..config })
    }

    /// Read and parse a `world.ini` file.
    pub fn read(path: &Path) -> Result<Self, LevelError> {
        Self::parse_bytes(&crate::error::read_file(path)?, path)
    }

    /// The file text: [`Self::ini`] line for line, with only the lines of
    /// interpreted keys whose value changed rewritten (an unchanged value
    /// keeps its original text).
    pub fn to_ini_text(&self) -> String {
        self.updated_ini().to_text()
    }

    /// The file bytes (in the encoding the file was read in).
    pub fn to_ini_bytes(&self) -> Vec<u8> {
        self.updated_ini().to_bytes()
    }

    fn updated_ini(&self) -> Ini {
        let mut ini = self.ini.clone();
        if ini == Ini::default() {
            ini = fostral_like_ini();
            // A new world's own values for the keys Fostral's text has.
            ini.set(
                GLOBAL,
                SECTION_SIZE_POWER,
                self.section_size_power().to_string(),
            );
        }
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
        ini
    }

    /// Write `world.ini`.
    pub fn write(&self, path: &Path) -> Result<(), LevelError> {
        crate::error::write_file(path, &self.to_ini_bytes())
    }
}

/// The keys the original game (`vrtMap::analyzeINI`) and vange-rs
/// (`LevelConfig::from_ini`) read, with Fostral's values, in Fostral's
/// order: a world written from scratch carries them so both loaders find
/// every key they require (the game aborts on a missing `Wave Terrain` or a
/// `Version` other than 1.4; vange-rs panics on any missing
/// `[Global Parameters]` power). `[Creation Parameters]` is read only by the
/// original map editor and is left out.
fn fostral_like_ini() -> Ini {
    let text = "[Global Parameters]\nMap Power X=11\nMap Power Y=14\nGeoNet Power=5\n\
        Section Size Power=7\nMinimal Square Power=4\n\n\
        [Storage]\nVersion=1.4\nCompressed Format Using=1\nFile Name=output\nPalette File=harmony.pal\n\n\
        [Rendering Parameters]\nShadow Offsets=10 12 4 9 6 4 4 4\nHeight Shifts=2 4 8 8 5 6 6 6\n\
        Begin Colors=1 32 64 72 88 104 112 120\nEnd Colors=31 63 71 87 103 111 119 127\n\n\
        [Dynamic Palette]\nWave Terrain=0\nTerrain Number=3\nTerrains=5 4 6\nSpeeds=128 128 256\n\
        Amplitudes=32 8 32\nRed=1 1 1\nGreen=0 1 1\nBlue=0 0 0\n";
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
        // Unchanged, the file comes back byte for byte (spacing, blank lines, order).
        assert!(
            text.as_bytes() == std::fs::read(fostral_path()).unwrap(),
            "{text}"
        );
        assert_eq!(WorldConfig::parse(&text, Path::new("x")).unwrap(), config);
        config.map_power_y = 10;
        config.compressed = false;
        config.end_colors[7] = 200;
        let changed = config.to_ini_text();
        // Only the three changed lines differ.
        let differ: Vec<(&str, &str)> = text
            .lines()
            .zip(changed.lines())
            .filter(|(a, b)| a != b)
            .collect();
        assert_eq!(
            differ,
            [
                ("Map Power Y=14", "Map Power Y=10"),
                ("Compressed Format Using=1", "Compressed Format Using=0"),
                (
                    "End Colors=    31 63 71 87 103 111 119 127",
                    "End Colors=31 63 71 87 103 111 119 200"
                ),
            ]
        );
        let again = WorldConfig::parse(&changed, Path::new("x")).unwrap();
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
