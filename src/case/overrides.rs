//! `--set KEY=VALUE` overrides, applied to the parsed TOML document before it is checked, so an
//! overridden value goes through exactly the same validation as one written in the file.
//!
//! KEY is a dotted path (`particles.dx_m`); entries of `[[...]]` lists are picked by index,
//! `fluid_block[0].min_m` or `fluid_block.0.min_m`. VALUE is parsed as a TOML value (`0.01`,
//! `[0.0, -9.81]`, `"laminar"`, `true`); if that fails it is taken as a bare string (`laminar`).

use toml::{Table, Value};

use super::error::{CaseError, Diagnostic};

/// Most names and indices in a key; the deepest field, `body[0].motion.pivot_m`, has 4.
const MAX_KEY_PARTS: usize = 8;

#[derive(Debug, Clone, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// One parsed `--set` argument.
#[derive(Debug, Clone)]
pub(super) struct Override {
    /// The raw argument, for messages.
    pub arg: String,
    /// The key normalised to `a.b[0].c`, as field paths are written in messages.
    pub key: String,
    segs: Vec<Seg>,
    value: Value,
}

fn fail(file: &str, arg: &str, problem: String, fix: &str) -> CaseError {
    Diagnostic {
        file: file.to_string(),
        line: None,
        column: None,
        set_by: Some(arg.to_string()),
        path: None,
        value: None,
        problem,
        fix: Some(fix.to_string()),
    }
    .into()
}

/// Parses `KEY=VALUE`.
pub(super) fn parse(file: &str, arg: &str) -> Result<Override, CaseError> {
    let Some((raw_key, raw_value)) = arg.split_once('=') else {
        return Err(fail(
            file,
            arg,
            "expected KEY=VALUE".into(),
            "write it like --set particles.dx_m=0.005",
        ));
    };
    let bad_key = |why: &str| {
        fail(
            file,
            arg,
            format!("`{}` is not a valid key: {why}", raw_key.trim()),
            "use a dotted field path such as particles.dx_m or probe[0].point_m",
        )
    };
    // An index picks an entry of the list named just before it; `apply` relies on that (a
    // list of lists, `probe.0.1`, has no tables to set a field in).
    let push_index = |segs: &mut Vec<Seg>, i: usize| match segs.last() {
        None => Err(bad_key("it cannot start with an index")),
        Some(Seg::Index(_)) => Err(bad_key(
            "an index must follow the name of a [[...]] list, as in probe[0].name",
        )),
        Some(Seg::Key(_)) => {
            segs.push(Seg::Index(i));
            Ok(())
        }
    };
    let mut segs = Vec::new();
    for part in raw_key.trim().split('.') {
        let (name, index) = match part.split_once('[') {
            Some((name, rest)) => {
                let digits = rest
                    .strip_suffix(']')
                    .ok_or_else(|| bad_key("unclosed `[`"))?;
                let i = digits
                    .parse::<usize>()
                    .map_err(|_| bad_key("the index in [...] must be a number"))?;
                (name, Some(i))
            }
            None => (part, None),
        };
        if name.is_empty() && index.is_none() {
            return Err(bad_key("empty part"));
        }
        if !name.is_empty() {
            if let Ok(i) = name.parse::<usize>() {
                push_index(&mut segs, i)?;
            } else if name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            {
                segs.push(Seg::Key(name.to_string()));
            } else {
                return Err(bad_key(
                    "only letters, digits, `_` and `-` may appear in names",
                ));
            }
        }
        if let Some(i) = index {
            push_index(&mut segs, i)?;
        }
    }
    if !matches!(segs.last(), Some(Seg::Key(_))) {
        return Err(bad_key("it must end with a field name"));
    }
    // `apply` creates the missing tables; thousands of them would overflow the stack when the
    // document is written out again.
    if segs.len() > MAX_KEY_PARTS {
        return Err(bad_key(&format!(
            "it has {} parts, but no case field is deeper than 4 (body[0].motion.pivot_m)",
            segs.len()
        )));
    }
    let mut key = String::new();
    for s in &segs {
        match s {
            Seg::Key(k) if key.is_empty() => key.push_str(k),
            Seg::Key(k) => {
                key.push('.');
                key.push_str(k);
            }
            Seg::Index(i) => key.push_str(&format!("[{i}]")),
        }
    }
    Ok(Override {
        arg: arg.to_string(),
        key,
        segs,
        value: parse_value(raw_value.trim()),
    })
}

/// A TOML value if `text` is one, else the text itself as a string.
fn parse_value(text: &str) -> Value {
    if let Ok(mut t) = format!("v = {text}").parse::<Table>() {
        if t.len() == 1 {
            if let Some(v) = t.remove("v") {
                return v;
            }
        }
    }
    Value::String(text.to_string())
}

/// Sets the override's value in `doc`, creating missing tables on the way.
pub(super) fn apply(file: &str, doc: &mut Table, ov: &Override) -> Result<(), CaseError> {
    let mut table = doc;
    let mut path = String::new();
    let mut i = 0;
    while i < ov.segs.len() {
        let Seg::Key(k) = &ov.segs[i] else {
            unreachable!("indices only follow keys (checked in parse)")
        };
        if !path.is_empty() {
            path.push('.');
        }
        path.push_str(k);
        if i + 1 == ov.segs.len() {
            table.insert(k.clone(), ov.value.clone());
            return Ok(());
        }
        if let Some(Seg::Index(n)) = ov.segs.get(i + 1) {
            let Some(Value::Array(items)) = table.get_mut(k) else {
                return Err(fail(
                    file,
                    &ov.arg,
                    format!("`{path}` is not a list of [[{k}]] tables in the file"),
                    "only existing [[...]] entries can be indexed; add the entry to the file",
                ));
            };
            let len = items.len();
            let Some(Value::Table(t)) = items.get_mut(*n) else {
                return Err(fail(
                    file,
                    &ov.arg,
                    format!(
                        "`{path}[{n}]` does not exist: the file has {len} entries (indices 0 \
                         to {})",
                        len.saturating_sub(1)
                    ),
                    "use an existing index, or add the entry to the file",
                ));
            };
            path.push_str(&format!("[{n}]"));
            table = t;
            i += 2;
        } else {
            let entry = table
                .entry(k.clone())
                .or_insert_with(|| Value::Table(Table::new()));
            match entry {
                Value::Table(t) => table = t,
                Value::Array(_) => {
                    return Err(fail(
                        file,
                        &ov.arg,
                        format!("`{path}` is a list of [[{k}]] tables"),
                        &format!("pick one entry by index, e.g. {k}[0].…"),
                    ))
                }
                _ => {
                    return Err(fail(
                        file,
                        &ov.arg,
                        format!("`{path}` is a value, not a table, so it has no fields"),
                        &format!("set `{path}` itself, e.g. --set {path}=…"),
                    ))
                }
            }
            i += 1;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_keys_and_values() {
        let o = parse("f", "particles.dx_m=0.005").unwrap();
        assert_eq!(o.key, "particles.dx_m");
        assert_eq!(o.value, Value::Float(0.005));
        let o = parse("f", "fluid_block.0.min_m = [0, 1]").unwrap();
        assert_eq!(o.key, "fluid_block[0].min_m");
        assert!(o.value.is_array());
        let o = parse("f", "physics.viscosity=laminar").unwrap();
        assert_eq!(o.value, Value::String("laminar".into()));
        let o = parse("f", "physics.viscosity=\"laminar\"").unwrap();
        assert_eq!(o.value, Value::String("laminar".into()));
        let o = parse("f", "probe[1].name=a=b").unwrap();
        assert_eq!(o.key, "probe[1].name");
        assert_eq!(o.value, Value::String("a=b".into()));
    }

    #[test]
    fn rejects_bad_keys() {
        let deep = format!("{}=1", vec!["a"; 10_000].join("."));
        for bad in [
            "dx",
            "=1",
            "a..b=1",
            "[0].a=1",
            "a[x].b=1",
            "a[0]=1",
            "a b=1",
            "0.a=1",
            // Two indices in a row (the fuzz test found that they reached `apply`'s
            // `unreachable!`).
            "probe.0.0.a=1",
            "probe[0].1.a=1",
            "probe.0[1].a=1",
            // Thousands of tables made by one --set overflowed the stack (an abort).
            &deep,
            "a.b.c.d.e.f.g.h.i=1",
        ] {
            let e = parse("f", bad).unwrap_err().to_string();
            assert!(e.contains("--set"), "{bad}: {e}");
        }
    }

    #[test]
    fn applies_and_reports_bad_paths() {
        let mut doc: Table = "[particles]\ndx_m = 1.0\n[[probe]]\nname='a'\n"
            .parse()
            .unwrap();
        apply("f", &mut doc, &parse("f", "particles.dx_m=0.5").unwrap()).unwrap();
        apply("f", &mut doc, &parse("f", "tank.layers=2").unwrap()).unwrap();
        apply("f", &mut doc, &parse("f", "probe[0].name=b").unwrap()).unwrap();
        assert_eq!(doc["particles"]["dx_m"].as_float(), Some(0.5));
        assert_eq!(doc["tank"]["layers"].as_integer(), Some(2));
        assert_eq!(doc["probe"][0]["name"].as_str(), Some("b"));
        for (arg, word) in [
            ("probe[3].name=x", "3 entries"),
            ("probe.name=x", "list"),
            ("particles.dx_m.x=1", "not a table"),
        ] {
            let e = apply("f", &mut doc, &parse("f", arg).unwrap()).unwrap_err();
            let text = e.to_string();
            assert!(
                text.contains(arg) && (text.contains(word) || word == "3 entries"),
                "{text}"
            );
        }
    }
}
