//! Buildings from footprints (`[[buildings]]`, docs/cases.md "Buildings"): the GeoJSON reader
//! of polygons (with holes) and their height property, and a footprint's geometry: which
//! points it holds (the even–odd rule over all its rings, so holes and either orientation
//! need no care) and how far a point lies from its outline.

use serde_json::Value;

/// A footprint: its rings (the outline and its holes; the closing vertex dropped) and its
/// height, when the feature gives one.
#[derive(Debug, Clone, PartialEq)]
pub struct Footprint {
    pub rings: Vec<Vec<[f64; 2]>>,
    pub height: Option<f64>,
    /// The feature it came from, counted from 0 in the file.
    pub feature: usize,
}

/// What is wrong with a footprint file: which feature (when one is to blame), what, and how to
/// fix it. The case's reader adds the file and the field.
#[derive(Debug, Clone, PartialEq)]
pub struct FootprintError {
    pub feature: Option<usize>,
    pub problem: String,
    pub fix: String,
}

fn error(feature: Option<usize>, problem: impl Into<String>, fix: &str) -> FootprintError {
    FootprintError {
        feature,
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// The footprints of a GeoJSON text: a FeatureCollection, a Feature or a bare geometry, each
/// geometry a Polygon or a MultiPolygon (one footprint each of its polygons), the height the
/// property `height_key` of the feature (a number, or a string that reads as one; absent or
/// null: none).
pub fn parse_geojson(text: &str, height_key: &str) -> Result<Vec<Footprint>, FootprintError> {
    let doc: Value = serde_json::from_str(text).map_err(|e| {
        error(
            None,
            format!("is not JSON: {e}"),
            "give a GeoJSON file (a GIS exports one: ogr2ogr -f GeoJSON out.geojson in.shp)",
        )
    })?;
    let features: Vec<&Value> = match doc.get("type").and_then(Value::as_str) {
        Some("FeatureCollection") => match doc.get("features").and_then(Value::as_array) {
            Some(f) => f.iter().collect(),
            None => {
                return Err(error(
                    None,
                    "is a FeatureCollection without a \"features\" array",
                    "give the features as an array",
                ))
            }
        },
        Some("Feature") | Some("Polygon") | Some("MultiPolygon") => vec![&doc],
        other => {
            return Err(error(
                None,
                format!(
                    "is not a GeoJSON FeatureCollection, Feature or Polygon (its \"type\" is \
                     {other:?})"
                ),
                "give the footprints as a GeoJSON FeatureCollection of Polygons",
            ))
        }
    };
    let mut out = Vec::new();
    for (i, f) in features.iter().enumerate() {
        let (geometry, properties) = match f.get("type").and_then(Value::as_str) {
            Some("Feature") => (f.get("geometry"), f.get("properties")),
            _ => (Some(*f), None),
        };
        let height = height_of(i, properties, height_key)?;
        let Some(geometry) = geometry.filter(|g| !g.is_null()) else {
            return Err(error(
                Some(i),
                "has no geometry",
                "give each building's footprint as a Polygon, or remove the feature",
            ));
        };
        let polygons: Vec<&Value> = match geometry.get("type").and_then(Value::as_str) {
            Some("Polygon") => geometry.get("coordinates").into_iter().collect(),
            Some("MultiPolygon") => geometry
                .get("coordinates")
                .and_then(Value::as_array)
                .map(|p| p.iter().collect())
                .unwrap_or_default(),
            other => {
                return Err(error(
                    Some(i),
                    format!("is a {other:?}, not a footprint (a Polygon or MultiPolygon)"),
                    "keep only the buildings' polygons in the file (a GIS selects them by \
                     geometry type)",
                ))
            }
        };
        if polygons.is_empty() {
            return Err(error(
                Some(i),
                "has no coordinates",
                "give the polygon's rings as \"coordinates\"",
            ));
        }
        for p in polygons {
            out.push(Footprint {
                rings: rings(i, p)?,
                height,
                feature: i,
            });
        }
    }
    if out.is_empty() {
        return Err(error(
            None,
            "holds no footprint",
            "give at least one building's Polygon",
        ));
    }
    Ok(out)
}

/// The height property of feature `i`.
fn height_of(
    i: usize,
    properties: Option<&Value>,
    key: &str,
) -> Result<Option<f64>, FootprintError> {
    let Some(v) = properties.and_then(|p| p.get(key)).filter(|v| !v.is_null()) else {
        return Ok(None);
    };
    let h = match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse::<f64>().ok(),
        _ => None,
    };
    match h {
        Some(h) if h.is_finite() && h > 0.0 => Ok(Some(h)),
        _ => Err(error(
            Some(i),
            format!("has the height {key:?} = {v}, not a positive number of metres"),
            "correct the feature's height, or remove the property to take the default height",
        )),
    }
}

/// The rings of a polygon's coordinates: each at least three distinct points, finite.
fn rings(i: usize, coordinates: &Value) -> Result<Vec<Vec<[f64; 2]>>, FootprintError> {
    let bad = |problem: String| {
        error(
            Some(i),
            problem,
            "give each ring as an array of [x, y] positions, the first repeated at the end",
        )
    };
    let Some(rings) = coordinates.as_array().filter(|r| !r.is_empty()) else {
        return Err(bad("has no rings".into()));
    };
    let mut out = Vec::with_capacity(rings.len());
    for (r, ring) in rings.iter().enumerate() {
        let mut points = Vec::new();
        for (k, p) in ring.as_array().into_iter().flatten().enumerate() {
            let xy = p.as_array().and_then(|c| {
                let x = c.first()?.as_f64()?;
                let y = c.get(1)?.as_f64()?;
                (x.is_finite() && y.is_finite()).then_some([x, y])
            });
            let Some(xy) = xy else {
                return Err(bad(format!("ring {r}: position {k} is not [x, y]: {p}")));
            };
            if points.last() != Some(&xy) {
                points.push(xy);
            }
        }
        if points.len() > 1 && points.first() == points.last() {
            points.pop();
        }
        if points.len() < 3 {
            return Err(bad(format!(
                "ring {r} has {} distinct positions; a ring needs at least 3",
                points.len()
            )));
        }
        out.push(points);
    }
    Ok(out)
}

impl Footprint {
    /// The rings' edges.
    fn edges(&self) -> impl Iterator<Item = ([f64; 2], [f64; 2])> + '_ {
        self.rings.iter().flat_map(|r| {
            r.iter()
                .zip(r.iter().cycle().skip(1))
                .map(|(a, b)| (*a, *b))
        })
    }

    /// Whether (x, y) lies inside: an odd number of the rings' edges cross the ray to +x (each
    /// edge taken half-open in y, so a vertex on the ray counts once).
    pub fn contains(&self, x: f64, y: f64) -> bool {
        self.edges()
            .filter(|(a, b)| {
                (a[1] > y) != (b[1] > y) && x < a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            })
            .count()
            % 2
            == 1
    }

    /// The distance from (x, y) to the nearest edge.
    pub fn distance_to_outline(&self, x: f64, y: f64) -> f64 {
        self.edges()
            .map(|(a, b)| {
                let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
                let len2 = ex * ex + ey * ey;
                let t = if len2 > 0.0 {
                    (((x - a[0]) * ex + (y - a[1]) * ey) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (x - a[0] - t * ex).hypot(y - a[1] - t * ey)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The area inside the outline (the first ring), holes not taken out: the shoelace
    /// formula.
    pub fn outline_area(&self) -> f64 {
        let ring = &self.rings[0];
        let twice: f64 = (0..ring.len())
            .map(|k| {
                let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        0.5 * twice.abs()
    }

    /// The box of the outline, (min, max).
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let all = self.rings.iter().flatten();
        let min = [0, 1].map(|a| all.clone().map(|p| p[a]).fold(f64::INFINITY, f64::min));
        let max = [0, 1].map(|a| all.clone().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max));
        (min, max)
    }

    /// The footprint moved by −(x, y) of `origin`.
    pub fn shifted(mut self, origin: [f64; 3]) -> Footprint {
        for p in self.rings.iter_mut().flatten() {
            *p = [p[0] - origin[0], p[1] - origin[1]];
        }
        self
    }
}

#[cfg(test)]
mod tests;
