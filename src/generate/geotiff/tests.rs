use std::io::{Cursor, Seek, Write};

use proptest::prelude::*;
use tiff::encoder::colortype::{self, ColorType as Samples};
use tiff::encoder::{
    Compression, DeflateLevel, DirectoryEncoder, TiffEncoder, TiffKind, TiffValue,
};
use tiff::tags::ExtraSamples;

use super::*;
use crate::generate::terrain::parse_asc;

/// terrain/tests.rs's grid: 3 × 2 cells 2 m wide whose south-west corner is at (100, 200).
const SMALL_ASC: &str = "ncols 3\nnrows 2\nxllcorner 100\nyllcorner 200\ncellsize 2\n\
                         NODATA_value -9999\n1 2 3\n4 5 6\n";

/// Its elevations, rows from the north as a GeoTIFF stores them too.
const SMALL: [f32; 6] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];

/// The GeoTIFF tags a test file carries (None: left out).
#[derive(Clone, Default)]
struct Geo {
    scale: Option<Vec<f64>>,
    tie_points: Option<Vec<f64>>,
    matrix: Option<Vec<f64>>,
    raster_type: Option<u16>,
    nodata: Option<&'static str>,
}

/// SMALL's georeferencing: raster point (0, 0), the north-west corner (PixelIsArea), at
/// (100, 204); cells of 2 m.
fn small_geo() -> Geo {
    Geo {
        scale: Some(vec![2.0, 2.0, 0.0]),
        tie_points: Some(vec![0.0, 0.0, 0.0, 100.0, 204.0, 0.0]),
        raster_type: Some(1),
        nodata: Some("-9999"),
        ..Geo::default()
    }
}

fn write_geo<W: Write + Seek, K: TiffKind>(dir: &mut DirectoryEncoder<'_, W, K>, geo: &Geo) {
    let doubles = [
        (Tag::ModelPixelScaleTag, &geo.scale),
        (Tag::ModelTiepointTag, &geo.tie_points),
        (Tag::ModelTransformationTag, &geo.matrix),
    ];
    for (tag, values) in doubles {
        if let Some(values) = values {
            dir.write_tag(tag, &values[..]).unwrap();
        }
    }
    if let Some(raster_type) = geo.raster_type {
        // Version 1.1.0, one key: GTRasterTypeGeoKey, its value in the key.
        let keys = [1u16, 1, 0, 1, RASTER_TYPE_KEY, 0, 1, raster_type];
        dir.write_tag(Tag::GeoKeyDirectoryTag, &keys[..]).unwrap();
    }
    if let Some(nodata) = geo.nodata {
        dir.write_tag(Tag::GdalNodata, nodata).unwrap();
    }
}

/// A GeoTIFF of `ncols` × `nrows` samples of type `C` (rows from the north), in strips.
fn geotiff<C: Samples>(
    (ncols, nrows): (u32, u32),
    samples: &[C::Inner],
    geo: &Geo,
    compression: Compression,
) -> Vec<u8>
where
    [C::Inner]: TiffValue,
{
    let mut file = Cursor::new(Vec::new());
    let mut tiff = TiffEncoder::new(&mut file)
        .unwrap()
        .with_compression(compression);
    let mut image = tiff.new_image::<C>(ncols, nrows).unwrap();
    write_geo(image.encoder(), geo);
    image.write_data(samples).unwrap();
    file.into_inner()
}

fn small_file(geo: &Geo) -> Vec<u8> {
    geotiff::<colortype::Gray32Float>((3, 2), &SMALL, geo, Compression::Uncompressed)
}

/// `grid` as a north-up GeoTIFF of f64 samples (PixelIsArea), as the case's tests give one.
pub(crate) fn geotiff_of(grid: &ElevationGrid) -> Vec<u8> {
    let (min, max) = grid.extent();
    let rows_from_north: Vec<f64> = grid.z.chunks(grid.ncols).rev().flatten().copied().collect();
    let geo = Geo {
        scale: Some(vec![grid.cell[0], grid.cell[1], 0.0]),
        tie_points: Some(vec![0.0, 0.0, 0.0, min[0], max[1], 0.0]),
        raster_type: Some(1),
        ..Geo::default()
    };
    let size = (grid.ncols as u32, grid.nrows as u32);
    geotiff::<colortype::Gray64Float>(size, &rows_from_north, &geo, Compression::Uncompressed)
}

/// A GeoTIFF of `ncols` × `nrows` f32 samples in uncompressed `tile` × `tile` tiles (GDAL's
/// TILED=YES), `value(col, row)` from the north-west; the edge tiles padded past the image.
fn tiled(ncols: u32, nrows: u32, tile: u32, value: impl Fn(u32, u32) -> f32, geo: &Geo) -> Vec<u8> {
    let mut file = Cursor::new(Vec::new());
    let mut tiff = TiffEncoder::new(&mut file).unwrap();
    let mut dir = tiff.image_directory().unwrap();
    let (mut offsets, mut counts) = (Vec::new(), Vec::new());
    for tile_row in 0..nrows.div_ceil(tile) {
        for tile_col in 0..ncols.div_ceil(tile) {
            let samples: Vec<f32> = (0..tile * tile)
                .map(|k| value(tile_col * tile + k % tile, tile_row * tile + k / tile))
                .collect();
            offsets.push(dir.write_data(&samples[..]).unwrap() as u32);
            counts.push(tile * tile * 4);
        }
    }
    dir.write_tag(Tag::ImageWidth, ncols).unwrap();
    dir.write_tag(Tag::ImageLength, nrows).unwrap();
    dir.write_tag(Tag::BitsPerSample, 32u16).unwrap();
    dir.write_tag(Tag::SampleFormat, 3u16).unwrap();
    dir.write_tag(Tag::SamplesPerPixel, 1u16).unwrap();
    dir.write_tag(Tag::PhotometricInterpretation, 1u16).unwrap();
    dir.write_tag(Tag::TileWidth, tile).unwrap();
    dir.write_tag(Tag::TileLength, tile).unwrap();
    dir.write_tag(Tag::TileOffsets, &offsets[..]).unwrap();
    dir.write_tag(Tag::TileByteCounts, &counts[..]).unwrap();
    write_geo(&mut dir, geo);
    dir.finish().unwrap();
    file.into_inner()
}

/// `bytes` (a little-endian TIFF) with the SHORT or LONG value of `tag` in its first
/// directory set to `value`.
fn patched(bytes: &[u8], tag: Tag, value: u32) -> Vec<u8> {
    assert_eq!(&bytes[..4], b"II*\0");
    let mut bytes = bytes.to_vec();
    let u16_at = |b: &[u8], at: usize| u16::from_le_bytes([b[at], b[at + 1]]);
    let ifd = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
    let entry = (0..usize::from(u16_at(&bytes, ifd)))
        .map(|k| ifd + 2 + 12 * k)
        .find(|&at| u16_at(&bytes, at) == tag.to_u16())
        .unwrap();
    match u16_at(&bytes, entry + 2) {
        3 => bytes[entry + 8..entry + 10].copy_from_slice(&(value as u16).to_le_bytes()),
        4 => bytes[entry + 8..entry + 12].copy_from_slice(&value.to_le_bytes()),
        other => panic!("{tag:?} has type {other}"),
    }
    bytes
}

#[test]
fn a_north_up_f32_geotiff_is_the_ascii_grid_of_the_same_cells() {
    let g = parse_geotiff(&small_file(&small_geo())).unwrap();
    assert_eq!(g, parse_asc(SMALL_ASC).unwrap());
    assert_eq!(g.first_centre, [101.0, 201.0]);
    // The file's last row is the southernmost.
    assert_eq!(g.z, vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0]);
}

#[test]
fn pixel_is_point_ties_a_cells_centre_and_a_tie_point_may_be_any_cell() {
    let point = Geo {
        raster_type: Some(2),
        ..small_geo()
    };
    let g = parse_geotiff(&small_file(&point)).unwrap();
    // (100, 204) is the north-west cell's centre: the south-west one's is a row south.
    assert_eq!(g.first_centre, [100.0, 202.0]);
    assert_eq!(g.cell, [2.0, 2.0]);
    // The same cells tied at raster point (2, 1) (a corner inside the grid) and without a
    // GeoKeyDirectory (PixelIsArea by default).
    let inner = Geo {
        tie_points: Some(vec![2.0, 1.0, 0.0, 104.0, 202.0, 0.0]),
        raster_type: None,
        ..small_geo()
    };
    assert_eq!(
        parse_geotiff(&small_file(&inner)).unwrap(),
        parse_asc(SMALL_ASC).unwrap()
    );
}

#[test]
fn no_data_and_non_finite_samples_become_nan() {
    let holed = [1.0, -9999.0, 3.0, 4.0, 5.0, f32::INFINITY];
    let file =
        geotiff::<colortype::Gray32Float>((3, 2), &holed, &small_geo(), Compression::Uncompressed);
    let g = parse_geotiff(&file).unwrap();
    assert_eq!(g.missing(), 2);
    // Row 1 from the north is the grid's row 0.
    assert!(g.z[2].is_nan() && g.z[4].is_nan());
    assert_eq!([g.z[0], g.z[1], g.z[3], g.z[5]], [4.0, 5.0, 1.0, 3.0]);
    // An f32 grid's no-data is the f32 nearest to the text (as GDAL compares it); "nan" marks
    // NaNs, which are no data anyway.
    for (nodata, sample) in [("-9999.9", -9999.9f32), (" nan ", f32::NAN)] {
        let geo = Geo {
            nodata: Some(nodata),
            ..small_geo()
        };
        let samples = [sample, 2.0, 3.0, 4.0, 5.0, 6.0];
        let file =
            geotiff::<colortype::Gray32Float>((3, 2), &samples, &geo, Compression::Uncompressed);
        let g = parse_geotiff(&file).unwrap();
        assert!(g.z[3].is_nan() && g.missing() == 1, "{nodata}: {:?}", g.z);
    }
}

#[test]
fn integer_and_f64_samples_in_any_compression_are_elevations() {
    let geo = Geo {
        nodata: Some("-32768"),
        ..small_geo()
    };
    let i16_rows = [1i16, 2, 3, 4, 5, -32768];
    let f64_rows = [1.25f64, 2.0, 3.0, 4.0, 5.0, -1e300];
    let files = [
        geotiff::<colortype::GrayI16>((3, 2), &i16_rows, &geo, Compression::Uncompressed),
        geotiff::<colortype::GrayI16>((3, 2), &i16_rows, &geo, Compression::Lzw),
        geotiff::<colortype::Gray64Float>(
            (3, 2),
            &f64_rows,
            &small_geo(),
            Compression::Deflate(DeflateLevel::Balanced),
        ),
        geotiff::<colortype::Gray64Float>((3, 2), &f64_rows, &small_geo(), Compression::Packbits),
    ];
    for (k, file) in files.iter().enumerate() {
        let g = parse_geotiff(file).unwrap();
        assert_eq!(g.first_centre, [101.0, 201.0], "file {k}");
        assert_eq!(
            [g.z[0], g.z[1], g.z[4], g.z[5]],
            [4.0, 5.0, 2.0, 3.0],
            "file {k}"
        );
        // The file's first sample (1 or 1.25) and last (no data, or -1e300).
        if k < 2 {
            assert!(g.z[3] == 1.0 && g.z[2].is_nan(), "file {k}: {:?}", g.z);
        } else {
            assert_eq!([g.z[3], g.z[2]], [1.25, -1e300], "file {k}");
        }
    }
    // A fraction marks no cell of an integer grid.
    let fraction = Geo {
        nodata: Some("4.5"),
        ..small_geo()
    };
    let file = geotiff::<colortype::GrayI16>((3, 2), &i16_rows, &fraction, Compression::Lzw);
    assert_eq!(parse_geotiff(&file).unwrap().missing(), 0);
}

#[test]
fn tiles_are_read_as_strips() {
    // 20 × 18 cells of 1 m in 16 × 16 tiles: four tiles, three cut at the image's edge.
    let value = |col: u32, row: u32| (100 * row + col) as f32;
    let geo = Geo {
        scale: Some(vec![1.0, 1.0, 0.0]),
        tie_points: Some(vec![0.0, 0.0, 0.0, 0.0, 18.0, 0.0]),
        ..Geo::default()
    };
    let g = parse_geotiff(&tiled(20, 18, 16, value, &geo)).unwrap();
    assert_eq!((g.ncols, g.nrows), (20, 18));
    assert_eq!(g.first_centre, [0.5, 0.5]);
    for (col, row_from_north) in [(0, 0), (19, 0), (15, 15), (16, 16), (19, 17), (3, 17)] {
        let row = 17 - row_from_north as usize;
        assert_eq!(
            g.z[row * 20 + col as usize],
            f64::from(value(col, row_from_north)),
            "({col}, {row_from_north})"
        );
    }
}

#[test]
fn a_transformation_places_non_square_cells_and_may_run_south_or_west() {
    // x = 10 + 1 I, y = 50 − 3 J: cells 1 m × 3 m, north-up.
    let north_up = vec![
        1.0, 0.0, 0.0, 10.0, 0.0, -3.0, 0.0, 50.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ];
    let geo = Geo {
        matrix: Some(north_up.clone()),
        ..Geo::default()
    };
    let g = parse_geotiff(&small_file(&geo)).unwrap();
    assert_eq!(g.cell, [1.0, 3.0]);
    // The south-west cell's centre: half a cell east of x = 10, a row and a half south of 50.
    assert_eq!(g.first_centre, [10.5, 45.5]);
    assert_eq!(g.z, vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0]);
    // The same cells stored from the south-east: the file's rows run north, its columns west.
    let mut from_south_east = north_up;
    from_south_east[0] = -1.0;
    from_south_east[3] = 13.0;
    from_south_east[5] = 3.0;
    from_south_east[7] = 44.0;
    let geo = Geo {
        matrix: Some(from_south_east),
        ..Geo::default()
    };
    let reversed = [6.0, 5.0, 4.0, 3.0, 2.0, 1.0];
    let file =
        geotiff::<colortype::Gray32Float>((3, 2), &reversed, &geo, Compression::Uncompressed);
    assert_eq!(parse_geotiff(&file).unwrap(), g);
    // Non-square by the pixel scale too.
    let geo = Geo {
        scale: Some(vec![1.0, 3.0, 0.0]),
        tie_points: Some(vec![0.0, 0.0, 0.0, 10.0, 50.0, 0.0]),
        ..Geo::default()
    };
    assert_eq!(parse_geotiff(&small_file(&geo)).unwrap(), g);
}

/// The problem of parsing `bytes`, which must be refused without a line.
fn refusal(bytes: &[u8]) -> String {
    match parse_geotiff(bytes) {
        Ok(g) => panic!("read: {g:?}"),
        Err(e) => {
            assert_eq!(e.line, None);
            assert!(!e.fix.is_empty());
            format!("{} / fix: {}", e.problem, e.fix)
        }
    }
}

#[test]
fn files_that_cannot_be_placed_are_refused_with_a_fix() {
    let rotated = vec![
        1.0, 0.1, 0.0, 10.0, 0.1, -1.0, 0.0, 50.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ];
    let cases: [(Geo, &[&str]); 8] = [
        (Geo::default(), &["no georeferencing", "ESRI ASCII"]),
        (
            Geo {
                tie_points: None,
                ..small_geo()
            },
            &["no georeferencing"],
        ),
        (
            Geo {
                scale: None,
                tie_points: Some(vec![
                    0.0, 0.0, 0.0, 1.0, 2.0, 0.0, 3.0, 1.0, 0.0, 7.0, 1.0, 0.0,
                ]),
                ..small_geo()
            },
            &["ground control points", "gdalwarp"],
        ),
        (
            Geo {
                matrix: Some(rotated),
                ..Geo::default()
            },
            &["rotated", "gdalwarp"],
        ),
        (
            Geo {
                scale: Some(vec![0.0, 2.0, 0.0]),
                ..small_geo()
            },
            &["step 0 along x", "finite size"],
        ),
        (
            Geo {
                scale: Some(vec![2.0, f64::NAN, 0.0]),
                ..small_geo()
            },
            &["NaN along y", "finite size"],
        ),
        (
            Geo {
                raster_type: Some(3),
                ..small_geo()
            },
            &["GTRasterTypeGeoKey is 3"],
        ),
        (
            Geo {
                nodata: Some("none"),
                ..small_geo()
            },
            &["GDAL_NODATA", "\"none\"", "gdal_edit.py"],
        ),
    ];
    for (geo, words) in cases {
        let e = refusal(&small_file(&geo));
        for w in words {
            assert!(e.contains(w), "`{w}` in: {e}");
        }
    }
}

#[test]
fn bands_sizes_and_formats_it_cannot_read_are_refused_with_a_fix() {
    let geo = small_geo();
    let two_bands = {
        let mut file = Cursor::new(Vec::new());
        let mut tiff = TiffEncoder::new(&mut file).unwrap();
        let mut image = tiff.new_image::<colortype::Gray32Float>(3, 2).unwrap();
        image.extra_samples(&[ExtraSamples::Unspecified]).unwrap();
        write_geo(image.encoder(), &geo);
        image.write_data(&[0.0; 12]).unwrap();
        file.into_inner()
    };
    let rgb = geotiff::<colortype::RGB8>((3, 2), &[0; 18], &geo, Compression::Uncompressed);
    let small = small_file(&geo);
    let huge = patched(
        &patched(&small, Tag::ImageWidth, 20_000),
        Tag::ImageLength,
        10_000,
    );
    let cases: [(Vec<u8>, &[&str]); 7] = [
        (two_bands, &["2 bands", "gdal_translate -b 1"]),
        (rgb, &["RGB", "gdal_translate -b 1"]),
        (huge, &["20000 × 10000 cells", "150000000", "coarser"]),
        (
            // JPEG-compressed (lossy): not decoded here.
            patched(&small, Tag::Compression, 7),
            &["tiff crate", "JPEG", "COMPRESS=DEFLATE"],
        ),
        (
            patched(&small, Tag::PhotometricInterpretation, 0),
            &["WhiteIsZero"],
        ),
        (small[..small.len() / 2].to_vec(), &["tiff crate"]),
        (b"ncols 3\nnrows 2\n".to_vec(), &["tiff crate", "AAIGrid"]),
    ];
    for (bytes, words) in cases {
        let e = refusal(&bytes);
        for w in words {
            assert!(e.contains(w), "`{w}` in: {e}");
        }
    }
}

proptest! {
    /// Whatever the bytes (a valid file cut short, with bytes changed), the reader answers
    /// with a grid or an error; a grid it answers with has the cells it says.
    #[test]
    fn any_bytes_are_read_or_refused(
        which in 0usize..3,
        changes in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..6),
        cut in any::<prop::sample::Index>(),
        cut_it in any::<bool>(),
    ) {
        let mut bytes = match which {
            0 => small_file(&small_geo()),
            1 => geotiff::<colortype::GrayI16>(
                (3, 2),
                &[1, 2, 3, 4, 5, 6],
                &small_geo(),
                Compression::Deflate(DeflateLevel::Fast),
            ),
            _ => tiled(20, 18, 16, |c, r| (c + r) as f32, &small_geo()),
        };
        for (at, byte) in changes {
            let at = at.index(bytes.len());
            bytes[at] = byte;
        }
        if cut_it {
            bytes.truncate(cut.index(bytes.len()));
        }
        if let Ok(g) = parse_geotiff(&bytes) {
            prop_assert_eq!(g.z.len(), g.ncols * g.nrows);
        }
    }
}
