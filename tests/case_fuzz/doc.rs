//! The seed cases and their TOML documents: every node (key or array element) with its
//! dotted path, edits, and what the schema says about a path (vector length, required).

use std::path::Path;
use std::sync::OnceLock;

use toml::{Table, Value};

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Seg {
    Key(String),
    Index(usize),
}

/// One key or array element of a seed document.
#[derive(Clone, Debug)]
pub(crate) struct Node {
    pub(crate) segs: Vec<Seg>,
    /// Dotted path as the loader writes it: `fluid_block[0].max_m[1]`.
    pub(crate) path: String,
    pub(crate) value: Value,
}

pub(crate) struct Seed {
    /// The path given to the loader (absolute, so that a series motion's CSV is found).
    pub(crate) file: String,
    pub(crate) text: String,
    pub(crate) doc: Table,
    pub(crate) dim: usize,
}

pub(crate) fn seeds() -> &'static [Seed] {
    static SEEDS: OnceLock<Vec<Seed>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        for dir in ["cases", "tests/data/case_fuzz"] {
            for entry in std::fs::read_dir(root.join(dir)).expect(dir) {
                let path = entry.expect(dir).path();
                if path.extension().is_some_and(|e| e == "toml") {
                    files.push(path);
                }
            }
        }
        files.sort();
        assert!(files.len() >= 8, "seeds: {files:?}");
        files
            .into_iter()
            .map(|path| {
                let text = std::fs::read_to_string(&path).expect("seed");
                let doc: Table = text.parse().expect("seed TOML");
                let dim = doc["dimension"].as_integer().expect("dimension") as usize;
                Seed {
                    file: path.display().to_string(),
                    text,
                    doc,
                    dim,
                }
            })
            .collect()
    })
}

pub(crate) fn path_of(segs: &[Seg]) -> String {
    let mut out = String::new();
    for s in segs {
        match s {
            Seg::Key(k) if out.is_empty() => out.push_str(k),
            Seg::Key(k) => {
                out.push('.');
                out.push_str(k);
            }
            Seg::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// Every key and array element of `doc`, depth first.
pub(crate) fn nodes(doc: &Table) -> Vec<Node> {
    fn walk(value: &Value, segs: &mut Vec<Seg>, out: &mut Vec<Node>) {
        match value {
            Value::Table(t) => {
                for (k, v) in t {
                    segs.push(Seg::Key(k.clone()));
                    out.push(node(segs, v));
                    walk(v, segs, out);
                    segs.pop();
                }
            }
            Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    segs.push(Seg::Index(i));
                    out.push(node(segs, v));
                    walk(v, segs, out);
                    segs.pop();
                }
            }
            _ => {}
        }
    }
    fn node(segs: &[Seg], v: &Value) -> Node {
        Node {
            segs: segs.to_vec(),
            path: path_of(segs),
            value: v.clone(),
        }
    }
    let mut out = Vec::new();
    walk(&Value::Table(doc.clone()), &mut Vec::new(), &mut out);
    out
}

/// The tables of `doc` (the root first), where an unknown field can be added.
pub(crate) fn tables(doc: &Table) -> Vec<Vec<Seg>> {
    let mut out = vec![Vec::new()];
    out.extend(
        nodes(doc)
            .into_iter()
            .filter(|n| n.value.is_table())
            .map(|n| n.segs),
    );
    out
}

pub(crate) fn node_mut<'a>(v: &'a mut Value, segs: &[Seg]) -> &'a mut Value {
    segs.iter().fold(v, |v, s| match s {
        Seg::Key(k) => v.get_mut(k.as_str()).expect("key"),
        Seg::Index(i) => v.get_mut(*i).expect("index"),
    })
}

/// `doc` with the node at `segs` replaced by `new`, or deleted (`None`).
pub(crate) fn edit(doc: &Table, segs: &[Seg], new: Option<Value>) -> Table {
    let mut root = Value::Table(doc.clone());
    let (last, parent) = segs.split_last().expect("not the root");
    let p = node_mut(&mut root, parent);
    match (last, new) {
        (Seg::Key(k), Some(v)) => {
            p.as_table_mut().expect("table").insert(k.clone(), v);
        }
        (Seg::Key(k), None) => {
            p.as_table_mut().expect("table").remove(k);
        }
        (Seg::Index(i), Some(v)) => p.as_array_mut().expect("array")[*i] = v,
        (Seg::Index(i), None) => {
            p.as_array_mut().expect("array").remove(*i);
        }
    }
    match root {
        Value::Table(t) => t,
        _ => unreachable!(),
    }
}

/// The path with indices written `[]` (`fluid_block[].min_m`), motions as `motion.<field>`.
pub(crate) fn generic(path: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for c in path.chars() {
        match c {
            '[' => {
                skip = true;
                out.push('[');
            }
            ']' => {
                skip = false;
                out.push(']');
            }
            _ if skip => {}
            _ => out.push(c),
        }
    }
    match out.find("motion.") {
        Some(i) => out[i..].to_string(),
        None => out,
    }
}

pub(crate) fn last_key(segs: &[Seg]) -> &str {
    segs.iter()
        .rev()
        .find_map(|s| match s {
            Seg::Key(k) => Some(k.as_str()),
            Seg::Index(_) => None,
        })
        .unwrap_or("")
}

/// Components of the vector field at `path` in a `dim`-D case, `None` if it is no vector.
pub(crate) fn vector_len(path: &str, dim: usize) -> Option<usize> {
    let g = generic(path);
    let key = g.rsplit('.').next().unwrap_or(&g);
    match key {
        "min_m" | "max_m" | "gravity_m_s2" | "velocity_m_s" | "center_m" | "point_m" | "face_m"
        | "base_m" | "origin_m" | "pivot_m" | "translation_m" | "seed_m" => Some(dim),
        "normal" if g.starts_with("probe") => Some(dim),
        "axis" if g == "motion.axis" => Some(3),
        "axis" => Some(dim),
        "angular_velocity_rad_s" => Some(if dim == 2 { 1 } else { 3 }),
        _ => None,
    }
}

/// Fields whose deletion must be refused with an error naming them: required by the schema,
/// or by the kind, shape or motion the seed gives (every such field present in a seed is
/// needed by it).
pub(crate) fn required(path: &str) -> bool {
    matches!(
        generic(path).as_str(),
        "dimension"
            | "particles"
            | "particles.dx_m"
            | "time"
            | "time.end_s"
            | "time.output_every_s"
            | "fluid_block"
            | "tank.min_m"
            | "tank.max_m"
            | "fluid_block[].min_m"
            | "fluid_block[].max_m"
            | "obstacle[].min_m"
            | "obstacle[].max_m"
            | "domain.min_m"
            | "domain.max_m"
            | "terrain.file"
            | "fill[].seed_m"
            | "fill[].level_m"
            | "surface[].file"
            | "probe[].name"
            | "probe[].kind"
            | "probe[].point_m"
            | "probe[].base_m"
            | "probe[].origin_m"
            | "probe[].axis"
            | "body[].name"
            | "inlet[].name"
            | "inlet[].min_m"
            | "inlet[].max_m"
            | "inlet[].direction"
            | "inlet[].velocity_m_s"
            | "body[].shape"
            | "body[].min_m"
            | "body[].max_m"
            | "body[].center_m"
            | "body[].radius_m"
            | "body[].file"
            | "body[].vertices_m"
            | "motion.kind"
            | "motion.period_s"
            | "motion.file"
    )
}
