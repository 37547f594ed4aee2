//! What a survey fits: the worlds and the qualities.

use std::path::PathBuf;
use strata_level::generate::{GenerateParams, Knobs};

/// The qualities the issue asks for.
pub const QUALITIES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// The default grid's dual fractions (issue 17: 0, 5, 10, 20, 30, 40 %).
pub const DUAL_FRACTIONS: [f64; 6] = [0.0, 0.05, 0.1, 0.2, 0.3, 0.4];
/// The default grid's floor-roughness factors: flat terraces, the default
/// world's relief, and three times it.
pub const FLOOR_ROUGHNESSES: [f64; 3] = [0.0, 1.0, 3.0];

/// One world of the survey.
#[derive(Clone, Debug, PartialEq)]
pub enum WorldSpec {
    /// Generated with knobs turned.
    Generated {
        params: GenerateParams,
        knobs: Knobs,
    },
    /// A world directory (`world.ini` + map + palette).
    Dir(PathBuf),
}

impl WorldSpec {
    /// The name the table shows.
    pub fn label(&self) -> String {
        match self {
            WorldSpec::Generated { knobs, .. } => format!(
                "dual {:.0}% rough {}",
                100.0 * knobs.dual_fraction.unwrap_or(0.0),
                knobs.floor_roughness.unwrap_or(1.0)
            ),
            WorldSpec::Dir(dir) => dir
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| dir.display().to_string()),
        }
    }
}

/// The worlds and qualities of one survey, and what the table shows.
#[derive(Clone, Debug)]
pub struct Plan {
    pub worlds: Vec<WorldSpec>,
    pub qualities: Vec<f64>,
    /// The quality of the ten-world table and the correlations (0.5).
    pub table_quality: f64,
    /// Fit with the slab outline as constraints.
    pub outline: bool,
}

impl Plan {
    /// The default generated grid: every dual fraction × every floor
    /// roughness, `width`x`height` each (2048x4096 by default; `--quick`
    /// takes 1024x2048), one seed.
    pub fn grid(seed: u64, width: u32, height: u32) -> Plan {
        let params = GenerateParams {
            seed,
            width,
            height,
        };
        let worlds = FLOOR_ROUGHNESSES
            .iter()
            .flat_map(|&r| {
                DUAL_FRACTIONS.iter().map(move |&f| WorldSpec::Generated {
                    params,
                    knobs: Knobs {
                        dual_fraction: Some(f),
                        floor_roughness: Some(r),
                    },
                })
            })
            .collect();
        Plan {
            worlds,
            qualities: QUALITIES.to_vec(),
            table_quality: 0.5,
            outline: false,
        }
    }

    /// World directories, e.g. the game's ten.
    pub fn dirs(dirs: Vec<PathBuf>) -> Plan {
        Plan {
            worlds: dirs.into_iter().map(WorldSpec::Dir).collect(),
            qualities: QUALITIES.to_vec(),
            table_quality: 0.5,
            outline: false,
        }
    }

    /// Fits the survey runs.
    pub fn steps(&self) -> usize {
        self.worlds.len() * self.qualities.len()
    }
}
