//! A run's flood maps (`[maps]`): `DIR/maps/<quantity>.asc`, ESRI ASCII grids in world
//! coordinates (the scenario's plus `world_origin_m`), NODATA (−9999) in every cell no sample
//! found wet, and for the velocities where the last sample found it dry.

use super::esri_ascii::asc_text;
use super::write_atomic;
use super::OutputError;
use crate::generate::terrain::{parse_asc, ElevationGrid};
use crate::layout::MapCell;
use crate::scenario::FloodMaps;
use anyhow::{anyhow, Context, Result};
use std::path::Path;

/// The folder of the maps inside the output directory.
pub const MAPS_DIR: &str = "maps";
/// The stem of the ground's map (`maps/ground_m.asc`), which the others are drawn over.
pub const GROUND_MAP: &str = "ground_m";

/// One map of a run: its file stem (`maps/<stem>.asc`), what it shows with its unit (a
/// picture's colour bar), and its grid.
#[derive(Clone, Debug, PartialEq)]
pub struct MapLayer {
    pub stem: &'static str,
    pub label: &'static str,
    pub grid: ElevationGrid,
}

/// Every quantity a map shows: its stem, label and value from a cell's record (NaN: NODATA).
type Quantity = (&'static str, &'static str, fn(&MapCell) -> f64);

const QUANTITIES: [Quantity; 7] = [
    ("max_depth_m", "maximum depth [m]", |c| wet(c, c.max_depth)),
    ("max_speed_m_s", "maximum speed [m/s]", |c| {
        wet(c, c.max_speed)
    }),
    ("max_hazard_m2_s", "maximum depth × speed [m²/s]", |c| {
        wet(c, c.max_hazard)
    }),
    ("arrival_s", "time of arrival [s]", |c| {
        if c.arrival >= 0.0 {
            decimal(c.arrival)
        } else {
            f64::NAN
        }
    }),
    ("final_depth_m", "final depth [m]", |c| wet(c, c.depth)),
    (
        "final_u_m_s",
        "final depth-averaged velocity, x [m/s]",
        |c| wet_now(c, c.u),
    ),
    (
        "final_v_m_s",
        "final depth-averaged velocity, y [m/s]",
        |c| wet_now(c, c.v),
    ),
];

/// `v` where some sample found the cell wet.
fn wet(c: &MapCell, v: f32) -> f64 {
    if c.wet_samples > 0 {
        decimal(v)
    } else {
        f64::NAN
    }
}

/// `v` where the last sample found the cell wet.
fn wet_now(c: &MapCell, v: f32) -> f64 {
    if c.depth > 0.0 {
        decimal(v)
    } else {
        f64::NAN
    }
}

/// The f64 of `v`'s shortest decimal (0.1f32 as 0.1, not 0.10000000149011612): the file then
/// holds the digits the GPU's f32 has, no more.
fn decimal(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(f64::NAN)
}

/// A grid of `maps`' cells in world coordinates (`origin`: the scenario's origin in the world).
fn grid_of(maps: &FloodMaps, origin: [f64; 3], z: Vec<f64>) -> ElevationGrid {
    ElevationGrid {
        ncols: maps.nx,
        nrows: maps.ny,
        first_centre: [0, 1].map(|a| maps.first_centre[a] + origin[a]),
        cell: [maps.cell; 2],
        z,
    }
}

/// The ground under the maps' cells, in world coordinates.
pub fn ground_layer(maps: &FloodMaps, origin: [f64; 3]) -> MapLayer {
    MapLayer {
        stem: GROUND_MAP,
        label: "ground [m]",
        grid: grid_of(
            maps,
            origin,
            maps.ground.iter().map(|z| z + origin[2]).collect(),
        ),
    }
}

/// What the map `stem` shows, with its unit (None: not a map a run writes).
pub fn map_label(stem: &str) -> Option<&'static str> {
    (QUANTITIES.iter())
        .find(|(s, _, _)| *s == stem)
        .map(|(_, label, _)| *label)
}

/// The maps of the records `cells` (row by row from the south).
pub fn map_layers(maps: &FloodMaps, cells: &[MapCell], origin: [f64; 3]) -> Vec<MapLayer> {
    (QUANTITIES.iter())
        .map(|&(stem, label, value)| MapLayer {
            stem,
            label,
            grid: grid_of(maps, origin, cells.iter().map(value).collect()),
        })
        .collect()
}

/// The stems of the maps a run in `dir` wrote (`maps/<stem>.asc`, the ground's included),
/// sorted; none when it has no maps.
pub fn map_stems(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir.join(MAPS_DIR)) else {
        return Vec::new();
    };
    let mut stems: Vec<String> = (entries.flatten())
        .filter_map(|e| e.file_name().into_string().ok())
        .filter_map(|n| n.strip_suffix(".asc").map(str::to_string))
        .collect();
    stems.sort();
    stems
}

/// The map `stem` of the run in `dir`, as written; errors name the file.
pub fn read_map(dir: &Path, stem: &str) -> Result<ElevationGrid> {
    let path = dir.join(MAPS_DIR).join(format!("{stem}.asc"));
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    parse_asc(&text).map_err(|e| {
        anyhow!(
            "{}{}: {}; fix: {}",
            path.display(),
            e.line.map(|l| format!(":{l}")).unwrap_or_default(),
            e.problem,
            e.fix
        )
    })
}

impl super::OutputDir {
    /// Writes `layers` to `DIR/maps/<stem>.asc`, each listed in the folder's manifest first.
    pub fn write_maps(&mut self, layers: &[MapLayer]) -> Result<()> {
        let folder = self.path().join(MAPS_DIR);
        std::fs::create_dir_all(&folder).map_err(|e| OutputError::io("create", &folder, e))?;
        for layer in layers {
            let path = folder.join(format!("{}.asc", layer.stem));
            let text = (asc_text(&layer.grid))
                .with_context(|| format!("writing the map {}", path.display()))?;
            self.claim(&path)?;
            write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
        }
        Ok(())
    }
}
