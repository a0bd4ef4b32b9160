//! GeoTIFF elevation grids (`[terrain]`, docs/cases.md "Terrain"), beside the ESRI ASCII grids
//! of [`super::terrain`]. The TIFF itself (strips or tiles; uncompressed, Deflate, LZW or
//! PackBits; 8- to 64-bit integer or floating-point samples) is decoded by the `tiff` crate
//! (image-rs); this module reads the GeoTIFF tags on top of it:
//!
//! - where the cells lie: ModelPixelScaleTag (33550) with the first tie point of
//!   ModelTiepointTag (33922), or a ModelTransformationTag (34264) without rotation or shear;
//! - GTRasterTypeGeoKey (1025, in GeoKeyDirectoryTag 34735): whether a raster point is a
//!   cell's corner (PixelIsArea, the default) or its centre (PixelIsPoint);
//! - GDAL_NODATA (42113): the value of the cells without data.
//!
//! The file's first image is read (the full resolution: overviews follow it). A file of
//! several bands, without georeferencing (or with ground control points only), rotated, or
//! with more than [`MAX_CELLS`] cells is refused, the size before any sample is decoded. The
//! coordinate system (the other geo keys) is not read: the grid is taken in its own units, as
//! an ESRI ASCII grid's.

use std::io::Cursor;

use tiff::decoder::{ifd::Value, Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::{ColorType, TiffError};

use super::terrain::{ElevationGrid, GridError, MAX_CELLS};

/// GTRasterTypeGeoKey's id in the GeoKeyDirectoryTag.
const RASTER_TYPE_KEY: u16 = 1025;

/// The fix for a file this reader cannot take.
const EXPORT_AGAIN: &str = "export the grid's band of elevations again as a GeoTIFF \
                            (gdal_translate -b 1 -co COMPRESS=DEFLATE in.tif out.tif), or as an \
                            ESRI ASCII grid (gdal_translate -of AAIGrid in.tif out.asc)";

/// The fix for a file whose cells cannot be placed.
const GEOREFERENCE: &str = "export the grid with its georeferencing (a GeoTIFF from GDAL or a \
                            GIS has it), or as an ESRI ASCII grid (gdal_translate -of AAIGrid \
                            in.tif out.asc)";

type Reader<'a> = Decoder<Cursor<&'a [u8]>>;

/// Reads a single-band GeoTIFF (`.tif`): its samples as elevations, the rows turned to run from
/// the south as [`ElevationGrid`]'s do. Samples equal to GDAL_NODATA, and non-finite ones,
/// become NaN. Errors have no line.
pub fn parse_geotiff(bytes: &[u8]) -> Result<ElevationGrid, GridError> {
    let mut reader = Decoder::new(Cursor::new(bytes))
        .map_err(unreadable)?
        .with_limits(limits(bytes.len()));
    let (ncols, nrows) = size(&mut reader)?;
    one_band(&mut reader)?;
    let placement = Placement::read(&mut reader)?;
    let nodata = nodata(&mut reader)?;
    let values = elevations(reader.read_image().map_err(unreadable)?, nodata);
    // One sample a cell, as one band of whole bytes decodes to: `grid` places each by its index.
    if values.len() != ncols * nrows {
        return Err(GridError::whole(
            format!(
                "the decoder gave {} samples for its {ncols} × {nrows} cells",
                values.len()
            ),
            EXPORT_AGAIN,
        ));
    }
    placement.grid(ncols, nrows, values)
}

/// The decoder's limits: room for the largest grid's samples at 8 bytes (the widest; its size
/// is checked before), and for a chunk as large as the file (one strip of an uncompressed grid).
fn limits(file_bytes: usize) -> Limits {
    let mut limits = Limits::default();
    limits.decoding_buffer_size = MAX_CELLS * std::mem::size_of::<f64>();
    limits.intermediate_buffer_size = file_bytes;
    limits
}

fn unreadable(e: TiffError) -> GridError {
    GridError::whole(
        format!("the tiff crate cannot read it as a TIFF grid: {e}"),
        EXPORT_AGAIN,
    )
}

fn tag_unreadable(tag: Tag, e: TiffError) -> GridError {
    GridError::whole(
        format!("its {tag:?} tag ({}) cannot be read: {e}", tag.to_u16()),
        EXPORT_AGAIN,
    )
}

/// The columns and rows, checked against [`MAX_CELLS`] before the samples are decoded.
fn size(reader: &mut Reader<'_>) -> Result<(usize, usize), GridError> {
    let (ncols, nrows) = reader.dimensions().map_err(unreadable)?;
    let cells = u64::from(ncols) * u64::from(nrows);
    if cells == 0 {
        return Err(GridError::whole(
            format!("it has {ncols} × {nrows} cells: no cell"),
            EXPORT_AGAIN,
        ));
    }
    if cells > MAX_CELLS as u64 {
        return Err(GridError::whole(
            format!("{ncols} × {nrows} cells are more than the {MAX_CELLS} a grid may have"),
            "resample the grid coarser (gdalwarp -tr <m> <m>: a cell need not be finer than the \
             particle spacing), or cut it to the flood's area (gdal_translate -projwin)",
        ));
    }
    Ok((ncols as usize, nrows as usize))
}

/// That the image is one band of 8- to 64-bit samples the decoder gives as they are stored.
fn one_band(reader: &mut Reader<'_>) -> Result<(), GridError> {
    let one_band_fix = "export the band of elevations alone: gdal_translate -b 1 in.tif out.tif";
    match reader.colortype().map_err(unreadable)? {
        ColorType::Gray(8 | 16 | 32 | 64) => {}
        ColorType::Gray(bits) => {
            return Err(GridError::whole(
                format!("its samples have {bits} bits; 8, 16, 32 or 64 are read"),
                "export the elevations as 32-bit floats: gdal_translate -ot Float32 in.tif \
                 out.tif",
            ))
        }
        ColorType::Multiband { num_samples, .. } => {
            return Err(GridError::whole(
                format!("it has {num_samples} bands (samples per pixel); a grid has one"),
                one_band_fix,
            ))
        }
        other => {
            return Err(GridError::whole(
                format!("it is an image of {other:?} pixels, not a grid of one band"),
                one_band_fix,
            ))
        }
    }
    // WhiteIsZero: the decoder would turn the samples upside down (max − value).
    let photometric = Tag::PhotometricInterpretation;
    match reader.find_tag_unsigned::<u16>(photometric) {
        Ok(Some(0)) => Err(GridError::whole(
            "its samples are stored as WhiteIsZero, an image's shades, not elevations",
            "export the grid again with gdal_translate -co PHOTOMETRIC=MINISBLACK in.tif out.tif",
        )),
        Ok(_) => Ok(()),
        Err(e) => Err(tag_unreadable(photometric, e)),
    }
}

/// Where a raster's cells lie: the world (x, y) of the centre of the file's first cell (its
/// first row's first column) and the step to the next cell's centre along the file's columns
/// and rows. A north-up raster's row step is negative: its rows run south.
struct Placement {
    first: [f64; 2],
    step: [f64; 2],
}

impl Placement {
    fn read(reader: &mut Reader<'_>) -> Result<Placement, GridError> {
        let (origin, step) = affine(reader)?;
        if !step.iter().all(|s| s.is_finite() && *s != 0.0) {
            return Err(GridError::whole(
                format!(
                    "its cells step {} along x and {} along y: a cell needs a finite size \
                     other than 0",
                    step[0], step[1]
                ),
                GEOREFERENCE,
            ));
        }
        let to_centre = corner_to_centre(reader)?;
        let first = [0, 1].map(|a| origin[a] + to_centre * step[a]);
        if !first.iter().all(|c| c.is_finite()) {
            return Err(GridError::whole(
                format!("its first cell lies at {first:?}, not at a finite point"),
                GEOREFERENCE,
            ));
        }
        Ok(Placement { first, step })
    }

    /// The grid of `values` (the file's rows in order, `ncols` each): its rows from the south
    /// and its columns from the west.
    fn grid(
        &self,
        ncols: usize,
        nrows: usize,
        values: Vec<f64>,
    ) -> Result<ElevationGrid, GridError> {
        let n = [ncols, nrows];
        // The file's last column (row) is the westernmost (southernmost) when it steps west
        // (south).
        let reversed = self.step.map(|s| s < 0.0);
        let first_centre = [0, 1].map(|a| {
            let last = self.first[a] + (n[a] - 1) as f64 * self.step[a];
            if reversed[a] {
                last
            } else {
                self.first[a]
            }
        });
        let mut z = vec![f64::NAN; values.len()];
        for (k, value) in values.into_iter().enumerate() {
            let (col, row) = (k % ncols, k / ncols);
            let col = if reversed[0] { ncols - 1 - col } else { col };
            let row = if reversed[1] { nrows - 1 - row } else { row };
            z[row * ncols + col] = value;
        }
        let grid = ElevationGrid {
            ncols,
            nrows,
            first_centre,
            cell: self.step.map(f64::abs),
            z,
        };
        let (min, max) = grid.extent();
        if !min.iter().chain(&max).all(|c| c.is_finite()) {
            return Err(GridError::whole(
                format!(
                    "its {ncols} × {nrows} cells of {:?} reach beyond the finite numbers",
                    grid.cell
                ),
                GEOREFERENCE,
            ));
        }
        Ok(grid)
    }
}

/// The world (x, y) of raster point (0, 0) (the first cell's corner or centre, as
/// [`corner_to_centre`] says) and the steps along the raster's columns and rows.
fn affine(reader: &mut Reader<'_>) -> Result<([f64; 2], [f64; 2]), GridError> {
    let scale = numbers(reader, Tag::ModelPixelScaleTag)?;
    let ties = numbers(reader, Tag::ModelTiepointTag)?;
    let matrix = numbers(reader, Tag::ModelTransformationTag)?;
    match (scale, ties, matrix) {
        (Some(scale), Some(ties), _) => from_tie_point(&scale, &ties),
        (_, _, Some(matrix)) => from_matrix(&matrix),
        (None, Some(_), None) => Err(GridError::whole(
            "it is placed by ground control points (tie points without a pixel scale), not on \
             a regular grid",
            "warp it onto a north-up grid: gdalwarp in.tif out.tif",
        )),
        _ => Err(GridError::whole(
            "it has no georeferencing: neither ModelPixelScaleTag with ModelTiepointTag nor \
             ModelTransformationTag, so where its cells lie is unknown",
            GEOREFERENCE,
        )),
    }
}

/// The scale (ScaleX, ScaleY, ScaleZ) and the first tie point (I, J, K, X, Y, Z): raster
/// point (I, J) lies at world (X, Y), and the raster's rows run south (y = Y − (j − J) ScaleY).
fn from_tie_point(scale: &[f64], ties: &[f64]) -> Result<([f64; 2], [f64; 2]), GridError> {
    let (&[sx, sy, ..], &[i, j, _, x, y, _, ..]) = (scale, ties) else {
        return Err(GridError::whole(
            format!(
                "its ModelPixelScaleTag holds {} numbers and its ModelTiepointTag {}: 3 and 6 \
                 (a tie point) are needed",
                scale.len(),
                ties.len()
            ),
            GEOREFERENCE,
        ));
    };
    Ok(([x - i * sx, y + j * sy], [sx, -sy]))
}

/// The 4 × 4 matrix, row by row, from raster (I, J, K, 1) to world (x, y, z, 1): north-up only
/// (x from I alone, y from J alone).
fn from_matrix(m: &[f64]) -> Result<([f64; 2], [f64; 2]), GridError> {
    let (16, &[sx, x_from_j, _, x0, y_from_i, sy, _, y0, ..]) = (m.len(), m) else {
        return Err(GridError::whole(
            format!(
                "its ModelTransformationTag holds {} numbers, not a 4 × 4 matrix's 16",
                m.len()
            ),
            GEOREFERENCE,
        ));
    };
    if x_from_j != 0.0 || y_from_i != 0.0 {
        return Err(GridError::whole(
            "its rows and columns are rotated (or sheared) against x and y: a grid's rows must \
             run west to east",
            "warp it north-up: gdalwarp in.tif out.tif",
        ));
    }
    Ok(([x0, y0], [sx, sy]))
}

/// The numbers of a tag (DOUBLE, as GeoTIFF writes them, or FLOAT); None when it is absent.
fn numbers(reader: &mut Reader<'_>, tag: Tag) -> Result<Option<Vec<f64>>, GridError> {
    let Some(value) = reader.find_tag(tag).map_err(|e| tag_unreadable(tag, e))? else {
        return Ok(None);
    };
    let number = |v: &Value| match *v {
        Value::Double(x) => Some(x),
        Value::Float(x) => Some(f64::from(x)),
        _ => None,
    };
    let numbers = match &value {
        Value::List(items) => items.iter().map(number).collect(),
        one => number(one).map(|x| vec![x]),
    };
    match numbers {
        Some(numbers) => Ok(Some(numbers)),
        None => Err(GridError::whole(
            format!(
                "its {tag:?} tag ({}) holds {value:?}, not numbers",
                tag.to_u16()
            ),
            GEOREFERENCE,
        )),
    }
}

/// How far the first cell's centre lies from raster point (0, 0), in cells along each axis,
/// by GTRasterTypeGeoKey: half a cell when the point is the cell's corner (PixelIsArea, 1,
/// the default), none when it is its centre (PixelIsPoint, 2).
fn corner_to_centre(reader: &mut Reader<'_>) -> Result<f64, GridError> {
    let tag = Tag::GeoKeyDirectoryTag;
    let keys = reader
        .find_tag_unsigned_vec::<u16>(tag)
        .map_err(|e| tag_unreadable(tag, e))?
        .unwrap_or_default();
    // A header of four shorts, then four a key: its id, where its value is (0: in the key),
    // the count and the value.
    let raster_type = keys
        .get(4..)
        .unwrap_or_default()
        .chunks_exact(4)
        .find(|key| key[0] == RASTER_TYPE_KEY && key[1] == 0)
        .map_or(1, |key| key[3]);
    match raster_type {
        1 => Ok(0.5),
        2 => Ok(0.0),
        other => Err(GridError::whole(
            format!(
                "its GTRasterTypeGeoKey is {other}, neither PixelIsArea (1) nor PixelIsPoint (2)"
            ),
            GEOREFERENCE,
        )),
    }
}

/// GDAL_NODATA: the value of the cells without data, if the file gives one.
fn nodata(reader: &mut Reader<'_>) -> Result<Option<f64>, GridError> {
    let tag = Tag::GdalNodata;
    let Some(value) = reader.find_tag(tag).map_err(|e| tag_unreadable(tag, e))? else {
        return Ok(None);
    };
    let number = match &value {
        Value::Ascii(text) => text.trim().parse::<f64>().ok(),
        _ => None,
    };
    match number {
        Some(n) => Ok(Some(n)),
        None => Err(GridError::whole(
            format!("its GDAL_NODATA tag (42113) holds {value:?}, not a number"),
            "set the value of the cells without data again: gdal_edit.py -a_nodata -9999 \
             file.tif (or -unsetnodata when every cell has data)",
        )),
    }
}

/// The samples as elevations: NaN where equal to `nodata`, compared in the samples' own type
/// as GDAL does (a 32-bit float grid's "-9999.9" is the f32 nearest to it; a fraction marks no
/// cell of an integer grid), and where not finite.
fn elevations(samples: DecodingResult, nodata: Option<f64>) -> Vec<f64> {
    match samples {
        DecodingResult::U8(v) => marked(v, nodata.and_then(whole), f64::from),
        DecodingResult::U16(v) => marked(v, nodata.and_then(whole), f64::from),
        DecodingResult::U32(v) => marked(v, nodata.and_then(whole), f64::from),
        DecodingResult::U64(v) => marked(v, nodata.and_then(whole), |x| x as f64),
        DecodingResult::I8(v) => marked(v, nodata.and_then(whole), f64::from),
        DecodingResult::I16(v) => marked(v, nodata.and_then(whole), f64::from),
        DecodingResult::I32(v) => marked(v, nodata.and_then(whole), f64::from),
        DecodingResult::I64(v) => marked(v, nodata.and_then(whole), |x| x as f64),
        DecodingResult::F16(v) => marked(v, nodata.map(half::f16::from_f64), f64::from),
        DecodingResult::F32(v) => marked(v, nodata.map(|n| n as f32), f64::from),
        DecodingResult::F64(v) => marked(v, nodata, |x| x),
    }
}

/// `n` as an integer of type `T`, when it is a whole number in its range.
fn whole<T: TryFrom<i128>>(n: f64) -> Option<T> {
    // `as` saturates: a value beyond i128 fails the conversion to T as well.
    (n.fract() == 0.0)
        .then(|| T::try_from(n as i128).ok())
        .flatten()
}

fn marked<T: Copy + PartialEq>(
    samples: Vec<T>,
    nodata: Option<T>,
    to_f64: impl Fn(T) -> f64,
) -> Vec<f64> {
    samples
        .into_iter()
        .map(|s| {
            let z = to_f64(s);
            if Some(s) == nodata || !z.is_finite() {
                f64::NAN
            } else {
                z
            }
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests;
