//! 3D snapshots as a person looks at a flood: a perspective view of every particle as a shaded
//! sphere, the fluid coloured by pressure or speed, walls, obstacles and bodies grey, with the
//! case, the time and a colour bar. Rendered offscreen with wgpu's render pipeline on the
//! run's own device (`shaders/splats.wgsl`), so a run draws its pictures where its particles
//! are, and a software adapter draws them in CI.
//!
//! The camera and the cutaway are fixed for a run, from its initial particles, so that frames
//! compare: the camera looks at the particles' bounding box from the front left and above and
//! frames the whole box; the walls on the camera's side of that box (the tank's near faces,
//! and a lid) are left out so that the water inside shows.

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use glam::{DMat4, DVec3};
use plotters::prelude::*;

use super::color_scale::{draw_colorbar, ColorScale, SnapshotField, BACKGROUND, COLORBAR_WIDTH};
use super::{register_font, write_png};
use crate::gpu::buffers::{map_read, readback_buffer};
use crate::gpu::GpuContext;
use crate::output::Snapshot;
use crate::scenario::{Kind, Scenario};
use crate::sph::EXCLUDED;

/// The 3D picture's size in pixels; the title and the colour bar are added around it.
pub const PICTURE: (u32, u32) = (960, 600);
/// Rendered at this many samples per pixel along each axis, then averaged: smooth edges
/// without multisampling, which not every adapter offers for every format.
const SUPERSAMPLING: u32 = 2;
const TITLE_HEIGHT: u32 = 34;
/// Vertical field of view.
const FOV_Y_DEG: f64 = 30.0;
/// Where the camera stands, from the centre of what it looks at (x along the tank, z up):
/// in front (−y), to the left (−x) and above.
const EYE_DIRECTION: [f64; 3] = [-0.45, -1.0, 0.7];
/// Boundary particles: light grey, so the coloured water stands out against them.
const WALL_RGB: [u8; 3] = [205, 205, 205];
/// Boundary particles within this many spacings of a face of their bounding box that the
/// camera looks through are left out (the tank's walls are up to 3 layers thick).
const CUT_LAYERS: f64 = 4.0;
/// A top face is a lid when its particles cover this share of the box's top.
const LID_COVER: f64 = 0.5;

/// A perspective camera: its frame and the matrix from world to clip space (wgpu's depth in
/// [0, 1]).
#[derive(Clone, Debug)]
pub struct Camera {
    /// Unit vector from the framed box's centre towards the camera.
    pub to_eye: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub view_proj: DMat4,
}

impl Camera {
    /// A camera looking along −`EYE_DIRECTION` (with `up` the world's vertical axis) at the
    /// box [`min`, `max`], as near as frames all eight corners in a picture of `aspect` =
    /// width / height, with a margin of 5 %.
    pub fn framing(min: DVec3, max: DVec3, up_axis: usize, aspect: f64) -> Result<Self> {
        if !(min.is_finite() && max.is_finite() && (max - min).min_element() >= 0.0) {
            bail!("camera framing of an empty or invalid box {min} – {max}");
        }
        let centre = 0.5 * (min + max);
        let world_up = DVec3::from_array(std::array::from_fn(|a| (a == up_axis) as u8 as f64));
        // EYE_DIRECTION is written for z up; for y up (a 2D-style case in 3D) z and y swap.
        let [ex, ey, ez] = EYE_DIRECTION;
        let to_eye = match up_axis {
            2 => DVec3::new(ex, ey, ez),
            _ => DVec3::new(ex, ez, -ey),
        }
        .normalize();
        let right = world_up.cross(to_eye).normalize();
        let up = to_eye.cross(right);
        let (tan_y, tan_x) = {
            let t = (0.5 * FOV_Y_DEG.to_radians()).tan();
            (t, t * aspect)
        };
        // A corner c (from the centre) stands at depth D − c·e in front of a camera at
        // centre + D e, and is in the picture while |c·right| ≤ depth tan_x, |c·up| ≤ depth tan_y.
        let mut distance: f64 = 0.0;
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { min.x } else { max.x },
                if k & 2 == 0 { min.y } else { max.y },
                if k & 4 == 0 { min.z } else { max.z },
            ) - centre;
            let depth_needed = (corner.dot(right).abs() / tan_x).max(corner.dot(up).abs() / tan_y);
            distance = distance.max(depth_needed + corner.dot(to_eye));
        }
        let distance = 1.05 * distance.max(1e-6);
        let eye = centre + distance * to_eye;
        let radius = 0.5 * (max - min).length();
        let (near, far) = ((distance - radius).max(1e-3 * distance), distance + radius);
        // World to camera (x right, y up, looking down −z), then the perspective projection
        // onto wgpu's clip space (depth from 0 at `near` to 1 at `far`).
        let view = DMat4::from_cols(
            right.extend(0.0),
            up.extend(0.0),
            to_eye.extend(0.0),
            eye.extend(1.0),
        )
        .inverse();
        let (fy, fx) = (1.0 / tan_y, 1.0 / tan_x);
        let proj = DMat4::from_cols_array(&[
            fx,
            0.0,
            0.0,
            0.0,
            0.0,
            fy,
            0.0,
            0.0,
            0.0,
            0.0,
            far / (near - far),
            -1.0,
            0.0,
            0.0,
            near * far / (near - far),
            0.0,
        ]);
        Ok(Camera {
            to_eye,
            right,
            up,
            view_proj: proj * view,
        })
    }

    /// Where `p` lands in a picture of `size` pixels: (column, row from the top), and whether
    /// it is in front of the camera.
    pub fn pixel(&self, p: DVec3, size: (u32, u32)) -> Option<(f64, f64)> {
        let clip = self.view_proj * p.extend(1.0);
        (clip.w > 0.0).then(|| {
            let (x, y) = (clip.x / clip.w, clip.y / clip.w);
            (
                0.5 * (x + 1.0) * size.0 as f64,
                0.5 * (1.0 - y) * size.1 as f64,
            )
        })
    }
}

/// Which boundary particles are left out so the water shows: those within [`CUT_LAYERS`]
/// spacings of the boundary's bounding box on the faces the camera looks through.
#[derive(Clone, Debug)]
struct Cutaway {
    /// Per axis: a particle is left out when beyond this bound (`lo` side: below; `hi`
    /// side: above); ±∞ where the face is kept.
    below: [f64; 3],
    above: [f64; 3],
}

impl Cutaway {
    fn of(sc: &Scenario, to_eye: DVec3, up_axis: usize) -> Self {
        let dx = sc.physics.dx;
        let boundary: Vec<[f64; 3]> = (sc.particles.iter())
            .filter(|p| !matches!(p.kind, Kind::Fluid | Kind::Inlet))
            .map(|p| p.pos)
            .collect();
        let mut cut = Cutaway {
            below: [f64::NEG_INFINITY; 3],
            above: [f64::INFINITY; 3],
        };
        if boundary.is_empty() {
            return cut;
        }
        let (lo, hi) = bounds(boundary.iter().copied());
        let depth = CUT_LAYERS * dx;
        for a in 0..3 {
            if a == up_axis {
                continue;
            }
            if to_eye[a] > 0.0 {
                cut.above[a] = hi[a] - depth;
            } else if to_eye[a] < 0.0 {
                cut.below[a] = lo[a] + depth;
            }
        }
        // A lid: boundary particles near the top over most of the box's horizontal area
        // inside its side walls (an open tank's rim is not a lid).
        let top = hi[up_axis] - depth;
        let across: Vec<usize> = (0..3).filter(|&a| a != up_axis).collect();
        let inside =
            |p: &[f64; 3]| (across.iter()).all(|&a| p[a] > lo[a] + depth && p[a] < hi[a] - depth);
        let area: f64 = (across.iter())
            .map(|&a| ((hi[a] - lo[a] - 2.0 * depth) / dx).max(0.0))
            .product();
        let columns: std::collections::HashSet<[i64; 2]> = (boundary.iter())
            .filter(|p| p[up_axis] > top && inside(p))
            .map(|p| [0, 1].map(|k| ((p[across[k]] - lo[across[k]]) / dx).round() as i64))
            .collect();
        if to_eye[up_axis] > 0.0 && columns.len() as f64 > LID_COVER * area {
            cut.above[up_axis] = top;
        }
        cut
    }

    fn hides(&self, p: &[f64; 3]) -> bool {
        (0..3).any(|a| p[a] < self.below[a] || p[a] > self.above[a])
    }
}

/// The smallest box holding `points`.
fn bounds(points: impl Iterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    points.fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(mut lo, mut hi), p| {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
            (lo, hi)
        },
    )
}

/// One particle as the vertex shader reads it.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SplatInstance {
    centre: [f32; 3],
    rgba: [u8; 4],
    radius: f32,
}

/// The camera as the shader reads it (`Camera` in splats.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CameraUniform {
    view_proj: [[f32; 4]; 4],
    right: [f32; 4],
    up: [f32; 4],
}

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// How a 3D run's snapshots are drawn: camera, cutaway, colours and the render pipeline,
/// fixed for the run.
pub struct PerspectiveView {
    case: String,
    field: SnapshotField,
    scale: ColorScale,
    camera: Camera,
    cut: Cutaway,
    /// Sphere radius of a particle, m: half a spacing, the fluid's a little more so that water
    /// reads as a body rather than beads.
    wall_radius: f32,
    fluid_radius: f32,
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    camera_group: wgpu::BindGroup,
    targets: Targets,
}

/// What every frame is rendered into and read back through, made once for the run.
struct Targets {
    /// Pixels: [`PICTURE`] times [`SUPERSAMPLING`].
    size: (u32, u32),
    color: wgpu::Texture,
    depth: wgpu::Texture,
    staging: wgpu::Buffer,
    /// Bytes of a row in `staging`: a texture copy's rows are padded to 256 bytes.
    padded_row: u32,
}

impl Targets {
    fn new(device: &wgpu::Device) -> Self {
        let size = (PICTURE.0 * SUPERSAMPLING, PICTURE.1 * SUPERSAMPLING);
        let target = |format, usage, label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.0,
                    height: size.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color = target(
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            "snapshot colour",
        );
        let depth = target(
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            "snapshot depth",
        );
        let padded_row = (4 * size.0).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = readback_buffer(device, "snapshot readback", (padded_row * size.1) as u64);
        Targets {
            size,
            color,
            depth,
            staging,
            padded_row,
        }
    }
}

impl PerspectiveView {
    /// The view of a run of `sc` (3D) on the device of `ctx`, with the run's fixed colours.
    pub fn for_scenario(ctx: &GpuContext, sc: &Scenario, field: SnapshotField) -> Result<Self> {
        if sc.physics.dim != 3 {
            bail!(
                "a perspective view is of a 3D case, not {}D",
                sc.physics.dim
            );
        }
        let scale = ColorScale::for_scenario(sc, field)?;
        let up_axis = up_axis(sc);
        let (lo, hi) = bounds(sc.particles.iter().map(|p| p.pos));
        let aspect = PICTURE.0 as f64 / PICTURE.1 as f64;
        let camera = Camera::framing(DVec3::from(lo), DVec3::from(hi), up_axis, aspect)?;
        let cut = Cutaway::of(sc, camera.to_eye, up_axis);
        let (device, queue) = (ctx.device.clone(), ctx.queue.clone());
        let (pipeline, camera_group) = pipeline(&device, &queue, &camera);
        let targets = Targets::new(&device);
        let dx = sc.physics.dx as f32;
        Ok(PerspectiveView {
            case: sc.name.clone(),
            field,
            scale,
            camera,
            cut,
            wall_radius: 0.5 * dx,
            fluid_radius: 0.6 * dx,
            device,
            queue,
            pipeline,
            camera_group,
            targets,
        })
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The particles drawn: excluded ones and the cut-away boundary left out.
    fn instances(&self, snap: &Snapshot) -> Vec<SplatInstance> {
        let fluid = [Kind::Fluid as u32, Kind::Inlet as u32];
        (0..snap.len())
            .filter(|&i| snap.kind[i] != EXCLUDED)
            .filter_map(|i| {
                let p = snap.pos[i];
                let is_fluid = fluid.contains(&snap.kind[i]);
                if !is_fluid && self.cut.hides(&p) {
                    return None;
                }
                let (rgb, radius) = if is_fluid {
                    let c = self.scale.color(self.field.value(snap, i));
                    ([c.0, c.1, c.2], self.fluid_radius)
                } else {
                    (WALL_RGB, self.wall_radius)
                };
                Some(SplatInstance {
                    centre: p.map(|c| c as f32),
                    rgba: [rgb[0], rgb[1], rgb[2], 255],
                    radius,
                })
            })
            .collect()
    }

    /// The 3D picture of `snap` alone: RGB, [`PICTURE`] pixels.
    pub fn picture(&self, snap: &Snapshot) -> Result<Vec<u8>> {
        snap.validate(Path::new("snapshot picture"))?;
        let rgba = self.render(&self.instances(snap))?;
        Ok(downsample(&rgba, self.targets.size, SUPERSAMPLING))
    }

    /// Renders `instances` into the render targets and reads the RGBA image back.
    fn render(&self, instances: &[SplatInstance]) -> Result<Vec<u8>> {
        let (device, t) = (&self.device, &self.targets);
        let bytes = bytemuck::cast_slice(instances);
        let vertices = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("snapshot splats"),
            size: (bytes.len() as u64).max(4),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&vertices, 0, bytes);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("snapshot"),
        });
        {
            let color_view = t.color.create_view(&Default::default());
            let depth_view = t.depth.create_view(&Default::default());
            let bg = |c: u8| c as f64 / 255.0;
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("snapshot splats"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: bg(BACKGROUND.0),
                            g: bg(BACKGROUND.1),
                            b: bg(BACKGROUND.2),
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.camera_group, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..4, 0..instances.len() as u32);
        }
        encoder.copy_texture_to_buffer(
            t.color.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &t.staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(t.padded_row),
                    rows_per_image: Some(t.size.1),
                },
            },
            t.color.size(),
        );
        self.queue.submit([encoder.finish()]);
        let data = map_read::<u8>(device, &t.staging)?;
        let row = 4 * t.size.0 as usize;
        let mut rgba = Vec::with_capacity(row * t.size.1 as usize);
        for r in 0..t.size.1 as usize {
            let start = r * t.padded_row as usize;
            rgba.extend_from_slice(&data[start..start + row]);
        }
        Ok(rgba)
    }

    fn title(&self, time_s: f64) -> String {
        format!(
            "{}   t = {time_s:.4} s   (walls on the camera's side cut away)",
            self.case
        )
    }

    /// The whole snapshot: the title with the time above the 3D picture, the colour bar beside
    /// it. RGB, with its size.
    pub fn render_snapshot(&self, snap: &Snapshot) -> Result<((u32, u32), Vec<u8>)> {
        let picture = self.picture(snap)?;
        register_font();
        let size = (PICTURE.0 + COLORBAR_WIDTH, PICTURE.1 + TITLE_HEIGHT);
        let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
        self.draw_frame(&mut rgb, size, snap.time_s)
            .map_err(|e| anyhow!("drawing the snapshot at t = {} s: {e}", snap.time_s))?;
        let row = PICTURE.0 as usize * 3;
        for r in 0..PICTURE.1 as usize {
            let at = ((r + TITLE_HEIGHT as usize) * size.0 as usize) * 3;
            rgb[at..at + row].copy_from_slice(&picture[r * row..(r + 1) * row]);
        }
        Ok((size, rgb))
    }

    /// The title and the colour bar, around where the picture goes.
    fn draw_frame<'b>(
        &self,
        rgb: &'b mut [u8],
        size: (u32, u32),
        time_s: f64,
    ) -> std::result::Result<(), Box<dyn std::error::Error + 'b>> {
        let root = BitMapBackend::with_buffer(rgb, size).into_drawing_area();
        root.fill(&BACKGROUND)?;
        let (title, body) = root.split_vertically(TITLE_HEIGHT);
        title.draw_text(
            &self.title(time_s),
            &("sans-serif", 20).into_text_style(&title),
            (12, 10),
        )?;
        let (_, bar) = body.split_horizontally(PICTURE.0);
        draw_colorbar(&bar, &self.scale, self.field.label())?;
        root.present()?;
        Ok(())
    }

    /// Renders `snap` and writes it to `path` as PNG, atomically.
    pub fn write_png(&self, path: &Path, snap: &Snapshot) -> Result<()> {
        let (size, rgb) = self.render_snapshot(snap)?;
        write_png(path, size, &rgb)
    }
}

/// The world's vertical axis: against gravity, z without it.
fn up_axis(sc: &Scenario) -> usize {
    let g = sc.physics.gravity;
    if g.iter().all(|&c| c == 0.0) {
        return 2;
    }
    (0..3)
        .max_by(|&a, &b| g[a].abs().total_cmp(&g[b].abs()))
        .unwrap_or(2)
}

/// The render pipeline of splats.wgsl and the camera's bind group.
fn pipeline(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    camera: &Camera,
) -> (wgpu::RenderPipeline, wgpu::BindGroup) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("splats.wgsl"),
        source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/splats.wgsl").into()),
    });
    let f32x4 = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
    let uniform = CameraUniform {
        view_proj: camera.view_proj.as_mat4().to_cols_array_2d(),
        right: f32x4(camera.right),
        up: f32x4(camera.up),
    };
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("snapshot camera"),
        size: std::mem::size_of::<CameraUniform>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, bytemuck::bytes_of(&uniform));
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("snapshot camera"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("snapshot camera"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("snapshot splats"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("snapshot splats"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("splat_vertex"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<SplatInstance>() as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &wgpu::vertex_attr_array![
                    0 => Float32x3, 1 => Unorm8x4, 2 => Float32
                ],
            })],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleStrip,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("splat_fragment"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    });
    (pipeline, group)
}

/// `rgba` of `size` averaged over `factor` × `factor` blocks, as RGB.
fn downsample(rgba: &[u8], size: (u32, u32), factor: u32) -> Vec<u8> {
    let (w, h, f) = (size.0 as usize, size.1 as usize, factor as usize);
    let (ow, oh) = (w / f, h / f);
    let mut out = Vec::with_capacity(ow * oh * 3);
    for y in 0..oh {
        for x in 0..ow {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..f {
                    for dx in 0..f {
                        sum += rgba[((y * f + dy) * w + x * f + dx) * 4 + c] as u32;
                    }
                }
                out.push(((sum + (f * f / 2) as u32) / (f * f) as u32) as u8);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every corner of the framed box lands inside the picture, and the box fills it along
    /// one axis at least to the margin (not framed from too far).
    #[test]
    fn the_camera_frames_the_whole_box() {
        for (min, max, up) in [
            ([0.0, 0.0, 0.0], [3.22, 1.0, 1.0], 2),
            ([-0.1, -0.1, -0.6], [2.6, 0.5, 0.5], 2),
            ([0.0, 0.0, 0.0], [1.0, 2.0, 0.5], 1),
        ] {
            let (min, max) = (DVec3::from(min), DVec3::from(max));
            let camera = Camera::framing(min, max, up, 1.6).unwrap();
            let size = (1600, 1000);
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for k in 0..8 {
                let pick = |bit: usize, a: usize| if k & bit == 0 { min[a] } else { max[a] };
                let corner = DVec3::new(pick(1, 0), pick(2, 1), pick(4, 2));
                let (c, r) = camera.pixel(corner, size).expect("in front of the camera");
                lo = [lo[0].min(c), lo[1].min(r)];
                hi = [hi[0].max(c), hi[1].max(r)];
            }
            assert!(lo[0] >= 0.0 && lo[1] >= 0.0, "{lo:?}");
            assert!(hi[0] <= size.0 as f64 && hi[1] <= size.1 as f64, "{hi:?}");
            let fill = ((hi[0] - lo[0]) / size.0 as f64).max((hi[1] - lo[1]) / size.1 as f64);
            assert!(fill > 0.85, "the box fills {fill} of the picture");
            // The vertical stays vertical: the top of the box above its bottom.
            let mut top = 0.5 * (min + max);
            let mut bottom = top;
            top[up] = max[up];
            bottom[up] = min[up];
            assert!(camera.pixel(top, size).unwrap().1 < camera.pixel(bottom, size).unwrap().1);
        }
        assert!(Camera::framing(DVec3::ONE, DVec3::ZERO, 2, 1.6).is_err());
    }

    #[test]
    fn downsampling_averages_blocks() {
        let rgba = [
            [10, 20, 30, 255],
            [30, 40, 50, 255],
            [50, 60, 70, 255],
            [70, 80, 92, 255],
        ]
        .concat();
        // (30 + 50 + 70 + 92) / 4 = 60.5 rounds to 61.
        assert_eq!(downsample(&rgba, (2, 2), 2), vec![40, 50, 61]);
    }
}
