use super::*;

/// A 10 m square with a 4 m square courtyard, and an L-shaped building, as a GIS exports them
/// (the L's height as a string, a third feature without one).
const TOWN: &str = r#"{
  "type": "FeatureCollection",
  "features": [
    {"type": "Feature", "properties": {"height": 12.5},
     "geometry": {"type": "Polygon", "coordinates": [
       [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]],
       [[3, 3], [3, 7], [7, 7], [7, 3], [3, 3]]]}},
    {"type": "Feature", "properties": {"height": "6"},
     "geometry": {"type": "MultiPolygon", "coordinates": [
       [[[20, 0], [30, 0], [30, 4], [24, 4], [24, 10], [20, 10], [20, 0]]]]}},
    {"type": "Feature", "properties": {"name": "shed"},
     "geometry": {"type": "Polygon", "coordinates": [[[40, 0, 5], [42, 0, 5], [42, 2, 5]]]}}
  ]
}"#;

#[test]
fn footprints_with_holes_and_heights_are_read() {
    let f = parse_geojson(TOWN, "height").unwrap();
    assert_eq!(f.len(), 3);
    assert_eq!(f[0].rings.len(), 2);
    assert_eq!(f[0].rings[0].len(), 4, "the closing vertex dropped");
    assert_eq!(
        (f[0].height, f[1].height, f[2].height),
        (Some(12.5), Some(6.0), None)
    );
    assert_eq!(f[1].feature, 1);
    // The courtyard is outside, the ring around it inside; the L's corner is outside.
    assert!(f[0].contains(1.0, 1.0) && !f[0].contains(5.0, 5.0) && !f[0].contains(11.0, 5.0));
    assert!(f[1].contains(22.0, 8.0) && !f[1].contains(27.0, 8.0) && f[1].contains(27.0, 2.0));
    assert!((f[0].distance_to_outline(5.0, 5.0) - 2.0).abs() < 1e-12);
    assert!((f[0].distance_to_outline(1.0, 5.0) - 1.0).abs() < 1e-12);
    assert_eq!(f[1].bounds(), ([20.0, 0.0], [30.0, 10.0]));
    let moved = f[0].clone().shifted([10.0, 20.0, 99.0]);
    assert!(moved.contains(-9.0, -19.0));
}

#[test]
fn a_point_on_a_vertexs_height_is_counted_once() {
    // A diamond: the ray from its centre runs through its east vertex.
    let d = parse_geojson(
        r#"{"type": "Polygon", "coordinates": [[[0, -1], [1, 0], [0, 1], [-1, 0]]]}"#,
        "h",
    )
    .unwrap();
    assert!(d[0].contains(0.0, 0.0));
    assert!(!d[0].contains(-2.0, 0.0) && !d[0].contains(2.0, 0.0));
}

#[test]
fn bad_footprints_name_the_feature_and_the_fix() {
    let cases: [(&str, Option<usize>, &str); 7] = [
        ("not json", None, "is not JSON"),
        (r#"{"type": "Topology"}"#, None, "\"Topology\""),
        (
            r#"{"type": "FeatureCollection", "features": []}"#,
            None,
            "no footprint",
        ),
        (
            r#"{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [0, 0]}}]}"#,
            Some(0),
            "\"Point\"",
        ),
        (
            r#"{"type": "Feature", "properties": {"height": -3}, "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1]]]}}"#,
            Some(0),
            "not a positive number",
        ),
        (
            r#"{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 0]]]}"#,
            Some(0),
            "2 distinct positions",
        ),
        (
            r#"{"type": "Polygon", "coordinates": [[[0, 0], [1, "a"], [1, 1]]]}"#,
            Some(0),
            "position 1 is not [x, y]",
        ),
    ];
    for (text, feature, words) in cases {
        let e = parse_geojson(text, "height").unwrap_err();
        assert_eq!(e.feature, feature, "{text}: {e:?}");
        assert!(e.problem.contains(words), "{text}: {}", e.problem);
        assert!(!e.fix.is_empty());
    }
}

proptest::proptest! {
    /// Whatever the text, the reader answers with footprints or an error.
    #[test]
    fn any_text_is_read_or_refused(text in "[\\[\\]{}\",:0-9a-zA-Z .-]{0,200}") {
        let _ = parse_geojson(&text, "height");
    }
}
