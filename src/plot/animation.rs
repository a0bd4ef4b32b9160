//! A run's snapshots as one animated PNG (APNG: every browser and image viewer plays it, and
//! an ordinary viewer shows its first frame), for sharing a run without ParaView.

use std::io::BufReader;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::output::{write_atomic, Manifest, SNAPSHOTS_DIR};

/// The animation's file in DIR/snapshots/.
pub const ANIMATION_FILE: &str = "animation.png";

/// Reads an 8-bit RGB PNG: its size and pixels.
fn read_rgb(path: &Path) -> Result<((u32, u32), Vec<u8>)> {
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut reader = png::Decoder::new(BufReader::new(file))
        .read_info()
        .with_context(|| format!("{} is not a PNG", path.display()))?;
    let info = reader.info();
    if (info.color_type, info.bit_depth) != (png::ColorType::Rgb, png::BitDepth::Eight) {
        bail!(
            "{}: an 8-bit RGB snapshot was expected, not {:?} {:?}",
            path.display(),
            info.color_type,
            info.bit_depth
        );
    }
    let size = (info.width, info.height);
    let mut rgb = vec![0; reader.output_buffer_size().unwrap_or(0)];
    reader
        .next_frame(&mut rgb)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok((size, rgb))
}

/// Writes `frames` (PNGs of one size, in order) as the animated PNG `DIR/snapshots/
/// animation.png`, `fps` frames a second, looping. Returns its path.
pub fn write_animation(dir: &Path, frames: &[PathBuf], fps: u16) -> Result<PathBuf> {
    let Some(first) = frames.first() else {
        bail!(
            "no snapshots to animate in {}",
            dir.join(SNAPSHOTS_DIR).display()
        );
    };
    if fps == 0 {
        bail!("an animation needs at least one frame a second");
    }
    let (size, _) = read_rgb(first)?;
    let path = dir.join(SNAPSHOTS_DIR).join(ANIMATION_FILE);
    Manifest::open(dir, 0)?.claim_path(&path)?;
    write_atomic(&path, |w| {
        let mut enc = png::Encoder::new(w, size.0, size.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_animated(frames.len() as u32, 0)
            .and_then(|()| enc.set_frame_delay(1, fps))
            .map_err(std::io::Error::other)?;
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        for frame in frames {
            let (frame_size, rgb) = read_rgb(frame).map_err(std::io::Error::other)?;
            if frame_size != size {
                return Err(std::io::Error::other(format!(
                    "{} is {}×{} pixels, the first snapshot {}×{}: every frame of an \
                     animation has one size",
                    frame.display(),
                    frame_size.0,
                    frame_size.1,
                    size.0,
                    size.1
                )));
            }
            writer
                .write_image_data(&rgb)
                .map_err(std::io::Error::other)?;
        }
        writer.finish().map_err(std::io::Error::other)
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(dir: &Path, name: &str, size: (u32, u32), value: u8) -> PathBuf {
        let path = dir.join(SNAPSHOTS_DIR).join(name);
        let rgb = vec![value; (size.0 * size.1 * 3) as usize];
        super::super::write_png(&path, size, &rgb).unwrap();
        path
    }

    /// Three frames in: an APNG of three frames at the asked rate, each frame's pixels those of
    /// its snapshot. A frame of another size is refused, naming it.
    #[test]
    fn snapshots_become_an_animated_png() {
        let dir = std::env::temp_dir().join(format!("wgsph-animation-{}", std::process::id()));
        std::fs::create_dir_all(dir.join(SNAPSHOTS_DIR)).unwrap();
        let frames: Vec<PathBuf> = (0..3)
            .map(|k| frame(&dir, &format!("{k:06}.png"), (4, 3), 40 * k as u8))
            .collect();
        let path = write_animation(&dir, &frames, 12).unwrap();
        let file = std::fs::File::open(&path).unwrap();
        let mut reader = png::Decoder::new(BufReader::new(file)).read_info().unwrap();
        let control = reader.info().animation_control.unwrap();
        assert_eq!((control.num_frames, control.num_plays), (3, 0));
        let mut rgb = vec![0; reader.output_buffer_size().unwrap()];
        for k in 0..3u8 {
            reader.next_frame(&mut rgb).unwrap();
            let fc = reader.info().frame_control.unwrap();
            assert_eq!((fc.delay_num, fc.delay_den), (1, 12));
            assert!(rgb.iter().all(|&v| v == 40 * k), "frame {k}");
        }
        let odd = frame(&dir, "odd.png", (5, 3), 0);
        let e = write_animation(&dir, &[frames[0].clone(), odd], 12).unwrap_err();
        assert!(format!("{e:#}").contains("odd.png is 5×3 pixels"), "{e:#}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
