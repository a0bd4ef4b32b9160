//! Particle snapshots as PNG (`wgsph run CASE --snapshots`): fluid particles as filled squares
//! of side dx coloured by pressure or speed, boundary particles grey, excluded particles not
//! drawn, with axes in metres and a colour bar.
//!
//! 2D draws the x–y plane. 3D draws a perspective view ([`super::perspective`]), or, asked for
//! (`wgsph plot DIR --snapshots --slice`), the x–z plane (z up) through a slice
//! |y − y_mid| < 2 dx at the middle of the domain, nearest the mid-plane drawn last: a
//! projection of the whole depth would show the tank's side walls in front of everything.
//!
//! The colour scale is fixed for a run so that frames compare: see [`ColorScale::for_scenario`].

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::color_scale::{
    draw_colorbar, plot_area, ColorScale, SnapshotField, BACKGROUND, COLORBAR_WIDTH, MARGIN,
    WALL_COLOR, X_LABEL_AREA,
};
use super::perspective::PerspectiveView;
use super::{register_font, write_png};
use crate::gpu::GpuContext;
use crate::output::{particle_files, Manifest, ParticleFile, Particles, Snapshot, SNAPSHOTS_DIR};
use crate::scenario::{Domain, Kind, OutputBoundary, Scenario};
use crate::sph::EXCLUDED;

/// What draws a run's snapshots: the plane of a 2D run or the x–z slice of a 3D one
/// ([`SnapshotView`]), or a 3D run's perspective view ([`PerspectiveView`], on a GPU device).
pub enum SnapshotPainter {
    Plane(SnapshotView),
    Perspective(Box<PerspectiveView>),
}

impl SnapshotPainter {
    /// The painter of a run of `sc`: 3D in perspective on `ctx`'s device unless `slice`.
    /// Errors for a 3D perspective without a device.
    pub fn for_scenario(
        ctx: Option<&GpuContext>,
        sc: &Scenario,
        field: SnapshotField,
        slice: bool,
    ) -> Result<Self> {
        if sc.physics.dim == 2 || slice {
            return Ok(SnapshotPainter::Plane(SnapshotView::for_scenario(
                sc, field,
            )?));
        }
        let ctx = ctx.ok_or_else(|| anyhow!("a 3D perspective snapshot needs a GPU adapter"))?;
        let view = PerspectiveView::for_scenario(ctx, sc, field)?;
        Ok(SnapshotPainter::Perspective(Box::new(view)))
    }

    /// Draws `snap` and writes it to `path` as PNG, atomically.
    pub fn write_png(&self, path: &Path, snap: &Snapshot) -> Result<()> {
        match self {
            SnapshotPainter::Plane(view) => view.write_png(path, snap),
            SnapshotPainter::Perspective(view) => view.write_png(path, snap),
        }
    }
}

/// Draws every particle file of the run of `sc` in `dir` (`DIR/particles/particles_NNNNNN.vtu`)
/// as `DIR/snapshots/NNNNNN.png` with `painter`, the pictures the run itself draws with
/// `--snapshots` when `painter` is its own: the same pictures, after the run (`wgsph plot DIR
/// --snapshots`). A file that left out the unmoved boundary particles
/// (`time.output_boundary = "first"`) is completed with those of the first file. Returns the
/// PNGs written.
pub fn draw_particle_files(
    dir: &Path,
    sc: &Scenario,
    painter: &SnapshotPainter,
) -> Result<Vec<PathBuf>> {
    let files = particle_files(dir)?;
    if files.is_empty() {
        bail!(
            "no particle files (particles/particles_NNNNNN.vtu) in {}",
            dir.display()
        );
    }
    let pngs = dir.join(SNAPSHOTS_DIR);
    std::fs::create_dir_all(&pngs).with_context(|| format!("cannot create {}", pngs.display()))?;
    let mut first: Option<ParticleFile> = None;
    let mut written = Vec::with_capacity(files.len());
    let mut manifest = Manifest::open(dir, 0)?;
    for (index, file) in &files {
        let png = pngs.join(format!("{index:06}.png"));
        manifest.claim_path(&png)?;
        let read = draw_particle_file(
            file,
            first.as_ref().map(|f| &f.particles),
            sc,
            painter,
            &png,
        )?;
        written.push(png);
        if *index == 0 {
            first = Some(read);
        }
    }
    Ok(written)
}

/// Draws the particle file `file` of the run of `sc` as `png` with `painter`; a file that left
/// out the unmoved boundary particles (`time.output_boundary = "first"`) is completed with
/// those of `first`, the run's first output. Returns what was read.
pub fn draw_particle_file(
    file: &Path,
    first: Option<&Particles>,
    sc: &Scenario,
    painter: &SnapshotPainter,
    png: &Path,
) -> Result<ParticleFile> {
    let read = ParticleFile::read(file)?;
    let partial = sc.time.output_boundary == OutputBoundary::First
        && read.particles.id.len() < sc.particles.len();
    let completed;
    let particles = match (first, partial) {
        (_, false) => &read.particles,
        (Some(f), true) => {
            completed = read.particles.completed_from(f);
            &completed
        }
        (None, true) => bail!(
            "{} holds {} of the run's {} particles (time.output_boundary = \"first\" left \
             out the unmoved walls), and the first output, which holds them, is missing",
            file.display(),
            read.particles.id.len(),
            sc.particles.len()
        ),
    };
    painter
        .write_png(png, &particles.snapshot(read.time_s, &[]))
        .with_context(|| format!("drawing {}", file.display()))?;
    Ok(read)
}

/// Pixels of the layout (see [`SnapshotView::render`]), beside `color_scale`'s margin, label
/// area and colour bar.
const TITLE_HEIGHT: u32 = 34;
const Y_LABEL_AREA: u32 = 70;
/// Longer side of the plotting area; the shorter one follows the domain's aspect ratio, but no
/// less than [`PLOT_MIN_SIDE`].
const PLOT_LONG_SIDE: f64 = 800.0;
const PLOT_MIN_SIDE: f64 = 150.0;

/// How a run's snapshots are drawn: fixed for the run.
#[derive(Clone, Debug)]
pub struct SnapshotView {
    case: String,
    field: SnapshotField,
    scale: ColorScale,
    /// Drawn region [m] along the image's horizontal axis (x) and vertical axis (y in 2D,
    /// z in 3D).
    x: Range<f64>,
    y: Range<f64>,
    /// World axis drawn vertically.
    up: usize,
    /// Side of a particle's square [m].
    dx: f64,
    /// 3D: only |y − centre| < half_width is drawn.
    slice: Option<(f64, f64)>,
}

/// A rendered snapshot: RGB pixels and where world coordinates land in them.
pub struct SnapshotImage {
    pub size: (u32, u32),
    pub rgb: Vec<u8>,
    coord: Cartesian2d<RangedCoordf64, RangedCoordf64>,
}

impl SnapshotImage {
    /// Pixel (column, row) of the drawn-plane point (x, y) [m].
    pub fn pixel(&self, x: f64, y: f64) -> (i32, i32) {
        self.coord.translate(&(x, y))
    }
}

impl SnapshotView {
    /// A view of `domain` in `dim` dimensions (2: the x–y plane; 3: the x–z plane, sliced at
    /// the domain's middle y), particles drawn as squares of side `dx`.
    pub fn new(
        case: &str,
        dim: u32,
        domain: &Domain,
        dx: f64,
        field: SnapshotField,
        scale: ColorScale,
    ) -> Result<Self> {
        if !(dim == 2 || dim == 3) {
            bail!("snapshots are drawn in 2 or 3 dimensions, not {dim}");
        }
        let up = dim as usize - 1;
        let (x, y) = (domain.min[0]..domain.max[0], domain.min[up]..domain.max[up]);
        if !(x.end > x.start && y.end > y.start && dx > 0.0) {
            bail!("snapshot of an empty domain ({x:?} × {y:?}) or with dx = {dx}");
        }
        let slice = (dim == 3).then(|| (0.5 * (domain.min[1] + domain.max[1]), 2.0 * dx));
        Ok(SnapshotView {
            case: case.to_string(),
            field,
            scale,
            x,
            y,
            up,
            dx,
            slice,
        })
    }

    /// The view of a run of `sc`, with the run's fixed colour scale.
    pub fn for_scenario(sc: &Scenario, field: SnapshotField) -> Result<Self> {
        let scale = ColorScale::for_scenario(sc, field)?;
        Self::new(
            &sc.name,
            sc.physics.dim,
            &sc.domain,
            sc.physics.dx,
            field,
            scale,
        )
    }

    /// Image size: the plotting area keeps the domain's aspect ratio.
    fn size(&self) -> (u32, u32) {
        let (lx, ly) = (self.x.end - self.x.start, self.y.end - self.y.start);
        let (pw, ph) = plot_area(lx, ly, PLOT_LONG_SIDE, PLOT_MIN_SIDE);
        (
            pw.round() as u32 + Y_LABEL_AREA + 2 * MARGIN + COLORBAR_WIDTH,
            ph.round() as u32 + X_LABEL_AREA + 2 * MARGIN + TITLE_HEIGHT,
        )
    }

    /// Indices of the particles drawn, in drawing order: boundary before fluid; in 3D, within
    /// each, farthest from the mid-plane first.
    fn drawing_order(&self, snap: &Snapshot) -> Vec<usize> {
        let dist = |i: usize| self.slice.map_or(0.0, |(c, _)| (snap.pos[i][1] - c).abs());
        let mut order: Vec<usize> = (0..snap.len())
            .filter(|&i| snap.kind[i] != EXCLUDED)
            .filter(|&i| self.slice.is_none_or(|(_, w)| dist(i) < w))
            .collect();
        let fluid = |i: usize| snap.kind[i] == Kind::Fluid as u32;
        order.sort_by(|&a, &b| fluid(a).cmp(&fluid(b)).then(dist(b).total_cmp(&dist(a))));
        order
    }

    fn title(&self, time_s: f64) -> String {
        match self.slice {
            None => format!("{}   t = {time_s:.4} s", self.case),
            Some((c, w)) => format!(
                "{}   t = {time_s:.4} s   slice |y − {c:.3}| < {w:.3} m",
                self.case
            ),
        }
    }

    /// Draws `snap` (see the module doc). Errors when an array does not have one entry per
    /// particle.
    pub fn render(&self, snap: &Snapshot) -> Result<SnapshotImage> {
        snap.validate(Path::new("snapshot image"))?;
        register_font();
        let size = self.size();
        let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
        let coord = self
            .draw(&mut rgb, size, snap)
            .map_err(|e| anyhow!("drawing the snapshot at t = {} s: {e}", snap.time_s))?;
        Ok(SnapshotImage { size, rgb, coord })
    }

    /// Renders `snap` and writes it to `path` as PNG, atomically.
    pub fn write_png(&self, path: &Path, snap: &Snapshot) -> Result<()> {
        let image = self.render(snap)?;
        write_png(path, image.size, &image.rgb)
    }

    fn draw<'b>(
        &self,
        rgb: &'b mut [u8],
        size: (u32, u32),
        snap: &Snapshot,
    ) -> std::result::Result<
        Cartesian2d<RangedCoordf64, RangedCoordf64>,
        Box<dyn std::error::Error + 'b>,
    > {
        let root = BitMapBackend::with_buffer(rgb, size).into_drawing_area();
        root.fill(&BACKGROUND)?;
        let (title, body) = root.split_vertically(TITLE_HEIGHT);
        title.draw_text(
            &self.title(snap.time_s),
            &("sans-serif", 20).into_text_style(&title),
            (MARGIN as i32 + Y_LABEL_AREA as i32, 10),
        )?;
        let (main, bar) = body.split_horizontally(size.0 - COLORBAR_WIDTH);
        let mut chart = ChartBuilder::on(&main)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(self.x.clone(), self.y.clone())?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .x_desc("x [m]")
            .y_desc(if self.up == 1 { "y [m]" } else { "z [m]" })
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()?;
        // A square of side dx grown by one pixel: moving particles are not on a lattice, and
        // plotters fills whole pixels from the floor of each corner, so squares of exactly dx
        // leave one-pixel seams, and ones narrower than a pixel would not be drawn at all.
        let (px, py) = chart.plotting_area().get_pixel_range();
        let half_x = 0.5 * (self.dx + (self.x.end - self.x.start) / (px.end - px.start) as f64);
        let half_y = 0.5 * (self.dx + (self.y.end - self.y.start) / (py.end - py.start) as f64);
        chart.draw_series(self.drawing_order(snap).into_iter().map(|i| {
            let (x, y) = (snap.pos[i][0], snap.pos[i][self.up]);
            let color = if snap.kind[i] == Kind::Fluid as u32 {
                self.scale.color(self.field.value(snap, i))
            } else {
                WALL_COLOR
            };
            Rectangle::new(
                [(x - half_x, y - half_y), (x + half_x, y + half_y)],
                color.filled(),
            )
        }))?;
        draw_colorbar(&bar, &self.scale, self.field.label())?;
        root.present()?;
        Ok(chart.as_coord_spec().clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Particles of a synthetic snapshot: (position, kind, pressure, velocity).
    struct Synthetic {
        pos: Vec<[f64; 3]>,
        kind: Vec<u32>,
        pressure: Vec<f32>,
        vel: Vec<[f32; 3]>,
    }

    impl Synthetic {
        fn new(particles: &[([f64; 3], u32, f32, [f32; 3])]) -> Self {
            Synthetic {
                pos: particles.iter().map(|p| p.0).collect(),
                kind: particles.iter().map(|p| p.1).collect(),
                pressure: particles.iter().map(|p| p.2).collect(),
                vel: particles.iter().map(|p| p.3).collect(),
            }
        }

        fn render(&self, view: &SnapshotView, rho: &[f32], id: &[u32]) -> SnapshotImage {
            let snap = Snapshot {
                time_s: 0.25,
                pos: &self.pos,
                vel: &self.vel,
                rho,
                pressure: &self.pressure,
                kind: &self.kind,
                id,
                extra: &[],
            };
            view.render(&snap).unwrap()
        }
    }

    fn pixel_at(img: &SnapshotImage, x: f64, y: f64) -> RGBColor {
        let (c, r) = img.pixel(x, y);
        let k = 3 * (r as usize * img.size.0 as usize + c as usize);
        RGBColor(img.rgb[k], img.rgb[k + 1], img.rgb[k + 2])
    }

    fn unit_box(dim: u32) -> Domain {
        Domain {
            min: [0.0; 3],
            max: if dim == 2 {
                [2.0, 1.0, 0.0]
            } else {
                [2.0, 1.0, 1.0]
            },
        }
    }

    #[test]
    fn renders_2d_fluid_walls_and_skips_excluded() {
        let scale = ColorScale::new(0.0, 1000.0).unwrap();
        let view = SnapshotView::new(
            "synthetic",
            2,
            &unit_box(2),
            0.1,
            SnapshotField::Pressure,
            scale,
        )
        .unwrap();
        let s = Synthetic::new(&[
            ([0.5, 0.5, 0.0], 0, 250.0, [0.0; 3]),
            ([1.5, 0.5, 0.0], 0, 1000.0, [0.0; 3]),
            ([1.0, 0.05, 0.0], 1, 0.0, [0.0; 3]),
            ([1.0, 0.8, 0.0], EXCLUDED, 500.0, [0.0; 3]),
        ]);
        let img = s.render(&view, &[1000.0; 4], &[0, 1, 2, 3]);
        // 2:1 domain: an 800 × 400 plotting area plus labels, title and colour bar.
        assert_eq!(img.size, view.size());
        assert_eq!(img.size, (800 + 70 + 24 + 130, 400 + 50 + 24 + 34));
        assert_eq!(pixel_at(&img, 0.5, 0.5), scale.color(250.0));
        assert_eq!(pixel_at(&img, 1.5, 0.5), scale.color(1000.0));
        // A square of side dx: 0.04 m off the centre is still the particle.
        assert_eq!(pixel_at(&img, 1.54, 0.46), scale.color(1000.0));
        assert_eq!(pixel_at(&img, 1.0, 0.05), WALL_COLOR);
        assert_eq!(pixel_at(&img, 1.0, 0.8), BACKGROUND, "excluded: not drawn");
        assert_eq!(pixel_at(&img, 0.5, 0.7), BACKGROUND);
        // The plotting area spans the domain, y up.
        let (c0, r0) = img.pixel(0.0, 0.0);
        let (c1, r1) = img.pixel(2.0, 1.0);
        assert!(c1 - c0 >= 795 && r0 - r1 >= 395, "{:?}", (c0, r0, c1, r1));
    }

    #[test]
    fn renders_3d_slice_in_x_z_by_speed() {
        let scale = ColorScale::new(0.0, 2.0).unwrap();
        let view = SnapshotView::new(
            "synthetic",
            3,
            &unit_box(3),
            0.1,
            SnapshotField::Speed,
            scale,
        )
        .unwrap();
        // y_mid = 0.5, half width 0.2. Two particles on the same (x, z): the one nearer the
        // mid-plane is drawn on top; one outside the slice is not drawn at all.
        let s = Synthetic::new(&[
            ([0.5, 0.5, 0.3], 0, 0.0, [1.0, 0.0, 0.0]),
            ([0.5, 0.65, 0.3], 0, 0.0, [0.0, 0.0, 2.0]),
            ([1.5, 0.9, 0.3], 0, 0.0, [0.0, 0.0, 2.0]),
            ([1.0, 0.45, 0.05], 1, 0.0, [0.0; 3]),
        ]);
        let img = s.render(&view, &[1000.0; 4], &[0, 1, 2, 3]);
        assert_eq!(img.size, (800 + 70 + 24 + 130, 400 + 50 + 24 + 34));
        assert_eq!(pixel_at(&img, 0.5, 0.3), scale.color(1.0));
        assert_eq!(pixel_at(&img, 1.5, 0.3), BACKGROUND);
        assert_eq!(pixel_at(&img, 1.0, 0.05), WALL_COLOR);
    }

    #[test]
    fn particles_smaller_than_a_pixel_are_drawn_and_neighbours_leave_no_seam() {
        let scale = ColorScale::new(0.0, 1.0).unwrap();
        // 2 m over 800 pixels: 2.5 mm per pixel.
        let tiny = SnapshotView::new(
            "tiny",
            2,
            &unit_box(2),
            1e-4,
            SnapshotField::Pressure,
            scale,
        )
        .unwrap();
        let s = Synthetic::new(&[([0.7, 0.7, 0.0], 0, 1.0, [0.0; 3])]);
        let img = s.render(&tiny, &[1000.0], &[0]);
        assert_eq!(pixel_at(&img, 0.7, 0.7), scale.color(1.0));
        // A row of particles 3 % further apart than dx, across many pixel boundaries.
        let dx = 0.013;
        let view =
            SnapshotView::new("row", 2, &unit_box(2), dx, SnapshotField::Pressure, scale).unwrap();
        let row: Vec<_> = (0..60)
            .map(|k| ([0.2 + 1.03 * dx * k as f64, 0.5, 0.0], 0, 1.0, [0.0; 3]))
            .collect();
        let img = Synthetic::new(&row).render(&view, &[1000.0; 60], &[0; 60]);
        let (c0, r) = img.pixel(0.2, 0.5);
        let (c1, _) = img.pixel(0.2 + 1.03 * dx * 59.0, 0.5);
        for c in c0..=c1 {
            let k = 3 * (r as usize * img.size.0 as usize + c as usize);
            assert_eq!(
                RGBColor(img.rgb[k], img.rgb[k + 1], img.rgb[k + 2]),
                scale.color(1.0),
                "seam at column {c}"
            );
        }
    }

    #[test]
    fn writes_a_png_of_the_rendered_size() {
        let dir = crate::output::test_util::temp_dir("snapshot-png");
        let scale = ColorScale::new(0.0, 1.0).unwrap();
        // A tall domain: 1 × 2 m.
        let domain = Domain {
            min: [0.0; 3],
            max: [1.0, 2.0, 0.0],
        };
        let view =
            SnapshotView::new("tall", 2, &domain, 0.05, SnapshotField::Pressure, scale).unwrap();
        let s = Synthetic::new(&[([0.5, 1.0, 0.0], 0, 0.5, [0.0; 3])]);
        let snap = Snapshot {
            time_s: 0.0,
            pos: &s.pos,
            vel: &s.vel,
            rho: &[1000.0],
            pressure: &s.pressure,
            kind: &s.kind,
            id: &[0],
            extra: &[],
        };
        let path = dir.join("000000.png");
        view.write_png(&path, &snap).unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(
            (info.width, info.height),
            (400 + 70 + 24 + 130, 800 + 50 + 24 + 34)
        );
        let img = view.render(&snap).unwrap();
        assert_eq!(&buf[..info.buffer_size()], img.rgb.as_slice());
        let (c, r) = img.pixel(0.5, 1.0);
        let k = 3 * (r as usize * info.width as usize + c as usize);
        assert_eq!(RGBColor(buf[k], buf[k + 1], buf[k + 2]), scale.color(0.5));
        // Only the PNG: no temporary file left.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        // A snapshot whose arrays disagree is an error, not a panic.
        let bad = Snapshot { kind: &[], ..snap };
        assert!(view.write_png(&dir.join("bad.png"), &bad).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
