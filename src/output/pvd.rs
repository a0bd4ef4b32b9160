//! ParaView `.pvd` collection listing the snapshot series.

use std::io::{self, Write};

use super::fmt_f64;

/// Writes the collection for `snapshots` = (time, file relative to the .pvd, '/' separators).
pub(crate) fn write_pvd(w: &mut dyn Write, snapshots: &[(f64, String)]) -> io::Result<()> {
    w.write_all(b"<?xml version=\"1.0\"?>\n")?;
    w.write_all(
        b"<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    )?;
    for (t, file) in snapshots {
        writeln!(
            w,
            "    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>",
            fmt_f64(*t),
            xml_escape(file)
        )?;
    }
    w.write_all(b"  </Collection>\n</VTKFile>\n")
}

pub(crate) fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Parses (timestep, file) pairs back out of a .pvd text.
    pub(crate) fn parse_pvd(text: &str) -> Vec<(f64, String)> {
        text.lines()
            .filter(|l| l.trim_start().starts_with("<DataSet "))
            .map(|l| {
                let attr = |name: &str| {
                    let key = format!(" {name}=\"");
                    let start = l.find(&key).unwrap() + key.len();
                    let len = l[start..].find('"').unwrap();
                    l[start..start + len].to_string()
                };
                (attr("timestep").parse().unwrap(), attr("file"))
            })
            .collect()
    }

    #[test]
    fn pvd_format_and_round_trip() {
        let snaps = vec![
            (0.0, "particles/particles_000000.vtu".to_string()),
            (0.01, "particles/particles_000001.vtu".to_string()),
            (0.1 + 0.2, "particles/particles_000002.vtu".to_string()),
        ];
        let mut buf = Vec::new();
        write_pvd(&mut buf, &snaps).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert!(text.contains(
            "<DataSet timestep=\"0.01\" group=\"\" part=\"0\" file=\"particles/particles_000001.vtu\"/>"
        ));
        assert!(text
            .contains("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">"));
        assert!(text.trim_end().ends_with("</VTKFile>"));
        let back = parse_pvd(&text);
        assert_eq!(back.len(), 3);
        for ((t0, f0), (t1, f1)) in snaps.iter().zip(&back) {
            assert_eq!(t0.to_bits(), t1.to_bits());
            assert_eq!(f0, f1);
        }
    }

    #[test]
    fn empty_and_nan() {
        let mut buf = Vec::new();
        write_pvd(&mut buf, &[]).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert!(text.contains("<Collection>\n  </Collection>"));
        let mut buf = Vec::new();
        write_pvd(&mut buf, &[(f64::NAN, "a&b.vtu".to_string())]).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert!(text.contains("timestep=\"nan\""));
        assert!(text.contains("file=\"a&amp;b.vtu\""));
    }
}
