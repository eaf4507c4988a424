//! The TOML layout of a parameter file:
//!
//! ```toml
//! name = "Benchmark bicycle"
//! model = "whipple"            # or "wobble"
//! source = "Meijaard et al. 2007, Table 1"
//!
//! [geometry]
//! wheelbase = { value = 1.02, unit = "m", source = "Table 1" }
//! ```
//!
//! Every section holds quantities; a quantity's name is `section.key`.

use std::fmt::Write;
use std::path::Path;

use toml::{Table, Value};

use super::{keys, ModelKind, ParamError, ParamSet, Problem, Quantity};

/// What a parameter file is expected to be, for a file that is not one.
pub(super) const EXPECTED: &str =
    "expected a TOML parameter file (`name`, `model` and `source`, then \
                        [sections] of quantities) or a BicycleParameters `*Benchmark.txt`";

pub(super) fn parse(path: &Path, text: &str) -> Result<ParamSet, ParamError> {
    let syntax = |param: &str, msg: String| ParamError {
        path: path.to_path_buf(),
        param: param.to_owned(),
        problem: Problem::Syntax(msg),
    };
    let table: Table = text.parse().map_err(|e: toml::de::Error| {
        syntax(
            "",
            format!("not a parameter file: {EXPECTED}; as TOML, {e}"),
        )
    })?;
    // TOML without any of the three names (an empty file, some other
    // program's settings) is not a parameter file missing one of them.
    if !["name", "model", "source"]
        .iter()
        .any(|k| table.contains_key(*k))
    {
        return Err(syntax("", format!("not a parameter file: {EXPECTED}")));
    }
    let string = |key: &str| -> Result<String, ParamError> {
        match table.get(key) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(_) => Err(syntax(key, "must be a string".into())),
            None => Err(syntax(
                key,
                "missing (every parameter file names it)".into(),
            )),
        }
    };
    let model = match string("model")?.as_str() {
        "whipple" => ModelKind::Whipple,
        "wobble" => ModelKind::Wobble,
        other => {
            return Err(syntax(
                "model",
                format!("{other:?} is not a model (whipple or wobble)"),
            ))
        }
    };
    let mut set = ParamSet::new(path, &string("name")?, model, &string("source")?);
    for (section, body) in &table {
        if matches!(section.as_str(), "name" | "model" | "source") {
            continue;
        }
        let Value::Table(entries) = body else {
            return Err(syntax(section, "expected a [section] of quantities".into()));
        };
        for (key, entry) in entries {
            let name = format!("{section}.{key}");
            if let Some(why) = keys::unknown(model, section, key) {
                return Err(syntax(&name, why));
            }
            let q = quantity(entry).map_err(|msg| syntax(&name, msg))?;
            set.insert(&name, q);
        }
    }
    if model == ModelKind::Wobble {
        for tyre in ["front_tyre", "rear_tyre"] {
            let own = format!("{tyre}.camber_relaxation_length");
            if set.quantity(&own).is_none() {
                set.notes.push(format!(
                    "{own} not given: the slip relaxation length {tyre}.relaxation_length is used"
                ));
            }
        }
    }
    Ok(set)
}

fn quantity(entry: &Value) -> Result<Quantity, String> {
    let Value::Table(t) = entry else {
        return Err("expected { value = ..., unit = \"...\", source = \"...\" }".into());
    };
    let value = match t.get("value") {
        Some(Value::Float(v)) => *v,
        Some(Value::Integer(v)) => *v as f64,
        _ => return Err("needs a numeric `value`".into()),
    };
    if !value.is_finite() {
        return Err("value is not a finite number".into());
    }
    let text = |k: &str| match t.get(k) {
        Some(Value::String(s)) => Ok(s.clone()),
        _ => Err(format!("needs a `{k}` string")),
    };
    if let Some(extra) = t
        .keys()
        .find(|k| !matches!(k.as_str(), "value" | "unit" | "source"))
    {
        return Err(format!("unexpected field `{extra}`"));
    }
    Ok(Quantity {
        value,
        unit: text("unit")?,
        source: text("source")?,
    })
}

/// The set as a TOML parameter file, in the layout [`parse`] reads.
#[must_use]
pub fn to_toml(set: &ParamSet) -> String {
    let quote = |s: &str| Value::String(s.to_owned()).to_string();
    let mut out = String::new();
    let _ = writeln!(out, "name = {}", quote(&set.name));
    let _ = writeln!(out, "model = {}", quote(set.model.name()));
    let _ = writeln!(out, "source = {}", quote(&set.source));
    let mut section = "";
    for (name, q) in set.iter() {
        let (sec, key) = name.split_once('.').unwrap_or(("params", name));
        if sec != section {
            let _ = writeln!(out, "\n[{sec}]");
            section = sec;
        }
        let _ = writeln!(
            out,
            "{key} = {{ value = {}, unit = {}, source = {} }}",
            Value::Float(q.value),
            quote(&q.unit),
            quote(&q.source)
        );
    }
    out
}
