//! Ground from an elevation grid (`[terrain]`, docs/cases.md "Terrain"): the ESRI ASCII grid
//! reader, the rules for cells without data, the bilinear surface through the cells' centres,
//! and the columns of wall particles under it.
//!
//! The wall follows the surface column by column: on the case's lattice of spacing dx, the
//! column at (x, y) holds particles at z_s(x, y) − (k + ½) dx, k = 0 … n − 1, so a gentle
//! slope is a smooth wall, not a staircase of whole cells. The depth n reaches every point of
//! the ground within L spacings of the surface (L layers across it): L √(1 + |∇z|²) spacings
//! under a uniform slope, the foot of a step plus L under its edge.

/// Most cells a grid may have (8 bytes each on the host: 1.2 GiB).
pub const MAX_CELLS: usize = 150_000_000;

/// An elevation grid: an elevation at each cell's centre, row by row from the south.
#[derive(Debug, Clone, PartialEq)]
pub struct ElevationGrid {
    pub ncols: usize,
    pub nrows: usize,
    /// The centre of the south-west cell (column 0 of the southernmost row).
    pub first_centre: [f64; 2],
    /// The cell size along x and y.
    pub cell: [f64; 2],
    /// Elevations, row by row from the south (y increasing), NaN where the file has no data.
    pub z: Vec<f64>,
}

/// What is wrong with a grid: where (the file's line, when one is to blame), what, and how to
/// fix it. The case's reader adds the file and the field.
#[derive(Debug, Clone, PartialEq)]
pub struct GridError {
    pub line: Option<usize>,
    pub problem: String,
    pub fix: String,
}

impl GridError {
    fn at(line: usize, problem: impl Into<String>, fix: impl Into<String>) -> GridError {
        GridError {
            line: Some(line),
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// An error of the whole file (no line to blame).
    pub(super) fn whole(problem: impl Into<String>, fix: impl Into<String>) -> GridError {
        GridError {
            line: None,
            problem: problem.into(),
            fix: fix.into(),
        }
    }
}

/// What cells without data become (`terrain.nodata`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NodataRule {
    /// A grid with a cell without data is refused (the default: a hole in the ground would
    /// drain the flood).
    Refuse,
    /// Each takes the elevation of the nearest cell with data (breadth first over the four
    /// neighbours, ties to the first reached: south, west, east, north).
    Nearest,
    /// Each takes this elevation [m].
    Elevation(f64),
}

/// The header keys of an ESRI ASCII grid, as the error for an unknown one lists them.
const HEADER_KEYS: &str = "ncols, nrows, xllcorner or xllcenter, yllcorner or yllcenter, \
                           cellsize (or dx and dy) and NODATA_value";

/// Reads an ESRI ASCII grid (`.asc`): the header (keys in any case and order), then `nrows`
/// rows of `ncols` elevations from the north, whitespace-separated (rows may wrap lines).
/// Values equal to `NODATA_value`, and non-finite ones, become NaN.
pub fn parse_asc(text: &str) -> Result<ElevationGrid, GridError> {
    let mut header = Header::default();
    let mut lines = text.lines().enumerate().peekable();
    while let Some(&(i, line)) = lines.peek() {
        let mut tokens = line.split_whitespace();
        let Some(key) = tokens.next() else {
            lines.next();
            continue;
        };
        if key.parse::<f64>().is_ok() {
            break;
        }
        header.read(i + 1, key, tokens.collect())?;
        lines.next();
    }
    let shape = header.shape(lines.peek().map_or(text.lines().count() + 1, |l| l.0 + 1))?;
    let (ncols, nrows) = (shape.ncols, shape.nrows);
    let mut z = vec![f64::NAN; ncols * nrows];
    let mut read = 0usize;
    let mut last_line = 0;
    for (i, line) in lines {
        for (k, token) in line.split_whitespace().enumerate() {
            let value: f64 =
                token.parse().map_err(|_| {
                    GridError::at(
                    i + 1,
                    format!("value {token:?} (number {} on the line) is not a number", k + 1),
                    "write elevations as numbers (a decimal point, not a comma), cells without \
                     data as NODATA_value",
                )
                })?;
            if read < z.len() {
                let (row_from_north, col) = (read / ncols, read % ncols);
                let no_data = !value.is_finite() || shape.nodata == Some(value);
                z[(nrows - 1 - row_from_north) * ncols + col] =
                    if no_data { f64::NAN } else { value };
            }
            read += 1;
        }
        last_line = i + 1;
    }
    if read != z.len() {
        return Err(GridError::at(
            last_line.max(1),
            format!(
                "the grid has {read} values where its header's ncols × nrows = {ncols} × \
                 {nrows} = {} asks for",
                z.len()
            ),
            "check ncols and nrows against the rows of values (a row cut short, or a header \
             that does not belong to this file)",
        ));
    }
    Ok(ElevationGrid {
        ncols,
        nrows,
        first_centre: shape.first_centre,
        cell: shape.cell,
        z,
    })
}

/// The header as read, before its keys are checked together.
#[derive(Default)]
struct Header {
    /// (key in lower case, value, line).
    keys: Vec<(String, f64, usize)>,
}

/// A checked header.
struct Shape {
    ncols: usize,
    nrows: usize,
    first_centre: [f64; 2],
    cell: [f64; 2],
    nodata: Option<f64>,
}

impl Header {
    fn read(&mut self, line: usize, key: &str, rest: Vec<&str>) -> Result<(), GridError> {
        let lower = key.to_ascii_lowercase();
        let known = [
            "ncols",
            "nrows",
            "xllcorner",
            "xllcenter",
            "yllcorner",
            "yllcenter",
            "cellsize",
            "dx",
            "dy",
            "nodata_value",
        ];
        if !known.contains(&lower.as_str()) {
            return Err(GridError::at(
                line,
                format!("{key:?} is not a key of an ESRI ASCII grid's header ({HEADER_KEYS})"),
                "give an ESRI ASCII grid (.asc, as GDAL and GIS programs export it); other \
                 grids convert with gdal_translate -of AAIGrid",
            ));
        }
        let value = match rest.as_slice() {
            [v] => v.parse::<f64>().ok().filter(|v| v.is_finite()),
            _ => None,
        };
        let Some(value) = value else {
            return Err(GridError::at(
                line,
                format!("{key} takes one finite number, not {:?}", rest.join(" ")),
                format!("write the line as `{key} <number>`"),
            ));
        };
        if self.keys.iter().any(|(k, _, _)| *k == lower) {
            return Err(GridError::at(
                line,
                format!("{key} is given twice"),
                "keep one of the two lines",
            ));
        }
        self.keys.push((lower, value, line));
        Ok(())
    }

    fn get(&self, key: &str) -> Option<(f64, usize)> {
        self.keys
            .iter()
            .find(|(k, _, _)| k == key)
            .map(|(_, v, l)| (*v, *l))
    }

    /// The header's keys checked together; `data_line` is the first line of values.
    fn shape(&self, data_line: usize) -> Result<Shape, GridError> {
        let count = |key: &str| -> Result<usize, GridError> {
            match self.get(key) {
                None => Err(GridError::at(
                    data_line,
                    format!("the header has no {key} before the values start"),
                    format!("add the line `{key} <number of cells>` to the header"),
                )),
                Some((v, l)) if v < 1.0 || v.fract() != 0.0 || v > MAX_CELLS as f64 => {
                    Err(GridError::at(
                        l,
                        format!("{key} = {v} is not a whole number of cells from 1 to {MAX_CELLS}"),
                        format!("give {key} as the grid's number of cells"),
                    ))
                }
                Some((v, _)) => Ok(v as usize),
            }
        };
        let (ncols, nrows) = (count("ncols")?, count("nrows")?);
        if ncols * nrows > MAX_CELLS {
            return Err(GridError::whole(
                format!("{ncols} × {nrows} cells are more than the {MAX_CELLS} a grid may have"),
                "resample the grid coarser (a cell need not be finer than the particle spacing), \
                 or cut it to the flood's area",
            ));
        }
        let cell = match (self.get("cellsize"), self.get("dx"), self.get("dy")) {
            (Some((c, l)), None, None) => [positive_size("cellsize", c, l)?; 2],
            (None, Some((x, lx)), Some((y, ly))) => {
                [positive_size("dx", x, lx)?, positive_size("dy", y, ly)?]
            }
            _ => {
                return Err(GridError::at(
                    data_line,
                    "the header gives no cell size: cellsize, or dx and dy, and not both",
                    "add the line `cellsize <m>`",
                ))
            }
        };
        let mut first_centre = [0.0; 2];
        for (a, axis) in ["x", "y"].iter().enumerate() {
            let corner = self.get(&format!("{axis}llcorner"));
            let centre = self.get(&format!("{axis}llcenter"));
            first_centre[a] = match (corner, centre) {
                (Some((c, _)), None) => c + 0.5 * cell[a],
                (None, Some((c, _))) => c,
                _ => {
                    return Err(GridError::at(
                        data_line,
                        format!(
                            "the header gives the south-west corner along {axis} neither or \
                             twice: {axis}llcorner (the cell's corner) or {axis}llcenter (its \
                             centre), one of them"
                        ),
                        format!("keep one line, `{axis}llcorner <m>` or `{axis}llcenter <m>`"),
                    ))
                }
            };
        }
        Ok(Shape {
            ncols,
            nrows,
            first_centre,
            cell,
            nodata: self.get("nodata_value").map(|(v, _)| v),
        })
    }
}

fn positive_size(key: &str, v: f64, line: usize) -> Result<f64, GridError> {
    if v > 0.0 {
        Ok(v)
    } else {
        Err(GridError::at(
            line,
            format!("{key} = {v} is not a positive length"),
            format!("give {key} as the cell's size in metres"),
        ))
    }
}

impl ElevationGrid {
    /// The cells without data.
    pub fn missing(&self) -> usize {
        self.z.iter().filter(|z| z.is_nan()).count()
    }

    /// The grid with every elevation given, by `rule`; an error when the rule refuses or no
    /// cell has data.
    pub fn filled(mut self, rule: NodataRule) -> Result<ElevationGrid, GridError> {
        let missing = self.missing();
        if missing == 0 {
            return Ok(self);
        }
        if missing == self.z.len() {
            return Err(GridError::whole(
                "no cell has data: every value is NODATA_value",
                "check NODATA_value against the values, or give the grid that holds the ground",
            ));
        }
        match rule {
            NodataRule::Refuse => {
                let first = self.z.iter().position(|z| z.is_nan()).unwrap_or(0);
                let (row, col) = (first / self.ncols, first % self.ncols);
                let [x, y] = self.centre(col, row);
                Err(GridError::whole(
                    format!(
                        "{missing} of its {} cells have no data (NODATA_value), the first in \
                         row {} from the north, column {}, its centre at x = {x} m, y = {y} m",
                        self.z.len(),
                        self.nrows - row,
                        col + 1,
                    ),
                    "set terrain.nodata = \"nearest\" (each takes the elevation of the nearest \
                     cell with data) or terrain.nodata = <elevation in m>, or fill the gaps in a \
                     GIS",
                ))
            }
            NodataRule::Elevation(e) => {
                self.z
                    .iter_mut()
                    .filter(|z| z.is_nan())
                    .for_each(|z| *z = e);
                Ok(self)
            }
            NodataRule::Nearest => {
                self.fill_nearest();
                Ok(self)
            }
        }
    }

    /// Breadth first from every cell with data: a cell without takes the value of the cell
    /// that reached it first.
    fn fill_nearest(&mut self) {
        let (nx, ny) = (self.ncols, self.nrows);
        let mut queue: std::collections::VecDeque<usize> =
            (0..self.z.len()).filter(|&i| !self.z[i].is_nan()).collect();
        while let Some(i) = queue.pop_front() {
            let (col, row) = (i % nx, i / nx);
            let neighbours = [
                (row > 0).then(|| i - nx),
                (col > 0).then(|| i - 1),
                (col + 1 < nx).then(|| i + 1),
                (row + 1 < ny).then(|| i + nx),
            ];
            for j in neighbours.into_iter().flatten() {
                if self.z[j].is_nan() {
                    self.z[j] = self.z[i];
                    queue.push_back(j);
                }
            }
        }
    }

    /// The centre of the cell in column `col` of row `row` (both from the south-west).
    pub fn centre(&self, col: usize, row: usize) -> [f64; 2] {
        [
            self.first_centre[0] + col as f64 * self.cell[0],
            self.first_centre[1] + row as f64 * self.cell[1],
        ]
    }

    /// The grid moved by −`origin` (x, y and elevations): world coordinates to the case's.
    pub fn shifted(mut self, origin: [f64; 3]) -> ElevationGrid {
        self.first_centre = [
            self.first_centre[0] - origin[0],
            self.first_centre[1] - origin[1],
        ];
        self.z.iter_mut().for_each(|z| *z -= origin[2]);
        self
    }

    /// The grid's extent along x and y: its cells' outer edges, (min, max).
    pub fn extent(&self) -> ([f64; 2], [f64; 2]) {
        let n = [self.ncols, self.nrows];
        let min = [0, 1].map(|a| self.first_centre[a] - 0.5 * self.cell[a]);
        let max = [0, 1].map(|a| self.first_centre[a] + (n[a] as f64 - 0.5) * self.cell[a]);
        (min, max)
    }

    /// The surface's elevation at (x, y): bilinear between the four nearest cells' centres,
    /// held beyond the outermost centres.
    pub fn elevation(&self, x: f64, y: f64) -> f64 {
        let (i0, i1, tx, _) = axis(x, self.first_centre[0], self.cell[0], self.ncols);
        let (j0, j1, ty, _) = axis(y, self.first_centre[1], self.cell[1], self.nrows);
        let z = |i: usize, j: usize| self.z[j * self.ncols + i];
        (1.0 - ty) * ((1.0 - tx) * z(i0, j0) + tx * z(i1, j0))
            + ty * ((1.0 - tx) * z(i0, j1) + tx * z(i1, j1))
    }

    /// The surface's gradient (∂z/∂x, ∂z/∂y) at (x, y) (zero along an axis beyond the
    /// outermost centres, where the surface is held).
    pub fn gradient(&self, x: f64, y: f64) -> [f64; 2] {
        let (i0, i1, tx, inside_x) = axis(x, self.first_centre[0], self.cell[0], self.ncols);
        let (j0, j1, ty, inside_y) = axis(y, self.first_centre[1], self.cell[1], self.nrows);
        let z = |i: usize, j: usize| self.z[j * self.ncols + i];
        let dzdx = (1.0 - ty) * (z(i1, j0) - z(i0, j0)) + ty * (z(i1, j1) - z(i0, j1));
        let dzdy = (1.0 - tx) * (z(i0, j1) - z(i0, j0)) + tx * (z(i1, j1) - z(i1, j0));
        [
            if inside_x { dzdx / self.cell[0] } else { 0.0 },
            if inside_y { dzdy / self.cell[1] } else { 0.0 },
        ]
    }

    /// The column of wall particles at (x, y) on a lattice of spacing `dx`, `layers` deep
    /// across the surface: down to the lowest point within `layers` spacings of the surface
    /// around it, sampled on the lattice (the points of the ground in the kernel's reach of
    /// water anywhere above).
    pub fn column(&self, x: f64, y: f64, dx: f64, layers: u32) -> Column {
        let surface = self.elevation(x, y);
        let l = i64::from(layers);
        let mut lowest = f64::INFINITY;
        for i in -l..=l {
            for j in -l..=l {
                let r2 = i * i + j * j;
                if r2 <= l * l {
                    let below = ((l * l - r2) as f64).sqrt() * dx;
                    let z = self.elevation(x + i as f64 * dx, y + j as f64 * dx) - below;
                    lowest = lowest.min(z);
                }
            }
        }
        let depth = ((surface - lowest) / dx - 1e-9).ceil();
        Column {
            surface,
            count: depth.max(f64::from(layers)) as usize,
        }
    }
}

/// The cells around `pos` along one axis of `n` centres from `first`, `cell` apart: the lower
/// and upper index, the fraction between them, and whether `pos` lies between the outermost
/// centres.
fn axis(pos: f64, first: f64, cell: f64, n: usize) -> (usize, usize, f64, bool) {
    let last = (n - 1) as f64;
    let u = (pos - first) / cell;
    let inside = (0.0..=last).contains(&u) && n > 1;
    let u = u.clamp(0.0, last);
    let i = (u.floor() as usize).min(n.saturating_sub(2));
    (i, (i + 1).min(n - 1), u - i as f64, inside)
}

/// The wall particles of one column: at `surface` − (k + ½) dx for k below `count`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Column {
    /// The surface's elevation at the column's centre.
    pub surface: f64,
    /// The particles in the column.
    pub count: usize,
}

impl Column {
    /// The elevation of the column's `k`-th particle, k = 0 the nearest the surface.
    pub fn particle_z(&self, k: usize, dx: f64) -> f64 {
        self.surface - (k as f64 + 0.5) * dx
    }

    /// The lowest particle's elevation.
    pub fn bottom(&self, dx: f64) -> f64 {
        self.particle_z(self.count.saturating_sub(1), dx)
    }
}

#[cfg(test)]
mod tests;
