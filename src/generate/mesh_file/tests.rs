use super::*;
use proptest::prelude::*;

const SQUARE: &str = "# a unit square as one quad\no square\nv 0 0 0\nv 1 0 0\nv 1 1 0\n\
                      vt 0 0\nvn 0 0 1\nv 0 1 0\nusemtl none\nf 1/1/1 2/1/1 3/1/1 4/1/1\n";

#[test]
fn an_obj_quad_is_two_triangles_of_its_vertices() {
    let m = parse_obj(SQUARE).unwrap();
    assert_eq!(m.vertices.len(), 4);
    assert_eq!(m.vertices[2], [1.0, 1.0, 0.0]);
    assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn negative_obj_indices_count_back_from_the_last_vertex() {
    let m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n").unwrap();
    assert_eq!(m.faces, vec![[0, 1, 2]]);
}

#[test]
fn bad_obj_lines_are_named() {
    let cases = [
        ("v 0 0\nf 1 1 1\n", 1, "has 2 coordinates"),
        ("v 0 0 x\n", 1, "\"x\" is not a number"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "fewer than three"),
        ("v 0 0 0\nf 1 2 3\n", 2, "names vertex 2"),
        ("v 0 0 0\nf 0 1 1\n", 2, "names vertex 0"),
        (
            "v 0 0 0\nf a 1 1\n",
            2,
            "does not start with a vertex index",
        ),
    ];
    for (text, line, says) in cases {
        let e = parse_obj(text).unwrap_err();
        assert_eq!(e.line, Some(line), "{text:?}: {e:?}");
        assert!(e.problem.contains(says), "{text:?}: {e:?}");
    }
    let e = parse(b"v 0 0 0\n", MeshFormat::Obj).unwrap_err();
    assert!(e.problem.contains("no triangles"), "{e:?}");
    let e = parse(b"v 0 0 inf\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::Obj).unwrap_err();
    assert!(e.problem.contains("finite"), "{e:?}");
}

#[test]
fn an_ascii_stl_shares_its_vertices() {
    let stl = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
               vertex 1 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\
               vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
    let m = parse(stl.as_bytes(), MeshFormat::Stl).unwrap();
    assert_eq!((m.vertices.len(), m.faces.len()), (4, 2));
}

#[test]
fn the_extension_names_the_format() {
    assert_eq!(MeshFormat::of_extension("STL"), Some(MeshFormat::Stl));
    assert_eq!(MeshFormat::of_extension("obj"), Some(MeshFormat::Obj));
    assert_eq!(MeshFormat::of_extension("ply"), None);
}

proptest! {
    /// Any bytes are read or refused, never a panic.
    #[test]
    fn no_bytes_make_the_readers_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400),
                                       cut in 0usize..400) {
        let _ = parse(&bytes, MeshFormat::Stl);
        let _ = parse(&bytes, MeshFormat::Obj);
        let obj = SQUARE.as_bytes();
        let _ = parse(&obj[..cut.min(obj.len())], MeshFormat::Obj);
    }
}
