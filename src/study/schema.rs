//! The documented layout of `study.json` (`docs/study-schema.json`, a JSON Schema) and a
//! checker for the part of JSON Schema it uses: `type` (one or a list), `required`,
//! `properties`, `additionalProperties` (false or a schema), `items`, `minimum` and local
//! `$ref`s into `$defs`.

use serde_json::Value;

/// `docs/study-schema.json`.
pub const SCHEMA: &str = include_str!("../../docs/study-schema.json");

/// Checks `doc` against `schema`; the error names the JSON path of the first problem.
pub fn validate(schema: &Value, doc: &Value) -> Result<(), String> {
    check(schema, schema, doc, "$")
}

/// Checks `doc` against [`SCHEMA`].
pub fn validate_study(doc: &Value) -> Result<(), String> {
    let schema: Value =
        serde_json::from_str(SCHEMA).map_err(|e| format!("study-schema.json: {e}"))?;
    validate(&schema, doc)
}

fn type_matches(t: &str, v: &Value) -> bool {
    match t {
        "object" => v.is_object(),
        "array" => v.is_array(),
        "string" => v.is_string(),
        "boolean" => v.is_boolean(),
        "null" => v.is_null(),
        "number" => v.is_number(),
        "integer" => v.is_u64() || v.is_i64() || v.as_f64().is_some_and(|f| f.fract() == 0.0),
        _ => false,
    }
}

fn check(root: &Value, s: &Value, v: &Value, path: &str) -> Result<(), String> {
    if let Some(r) = s.get("$ref").and_then(Value::as_str) {
        let name = r
            .strip_prefix("#/$defs/")
            .ok_or_else(|| format!("schema: unsupported $ref {r}"))?;
        let target = root
            .get("$defs")
            .and_then(|d| d.get(name))
            .ok_or_else(|| format!("schema: no definition {r}"))?;
        return check(root, target, v, path);
    }
    if let Some(t) = s.get("type") {
        let ok = match t {
            Value::String(t) => type_matches(t, v),
            Value::Array(ts) => ts
                .iter()
                .filter_map(Value::as_str)
                .any(|t| type_matches(t, v)),
            _ => return Err(format!("schema: bad type at {path}")),
        };
        if !ok {
            return Err(format!("{path}: expected {t}, found {v}"));
        }
    }
    if let (Some(min), Some(x)) = (s.get("minimum").and_then(Value::as_f64), v.as_f64())
        && x < min
    {
        return Err(format!("{path}: {x} is below the minimum {min}"));
    }
    if let Some(obj) = v.as_object() {
        if let Some(req) = s.get("required").and_then(Value::as_array) {
            for k in req.iter().filter_map(Value::as_str) {
                if !obj.contains_key(k) {
                    return Err(format!("{path}: missing required field `{k}`"));
                }
            }
        }
        let props = s.get("properties").and_then(Value::as_object);
        for (k, x) in obj {
            let sub = format!("{path}.{k}");
            match props.and_then(|p| p.get(k)) {
                Some(ps) => check(root, ps, x, &sub)?,
                None => match s.get("additionalProperties") {
                    Some(Value::Bool(false)) => {
                        return Err(format!("{path}: unexpected field `{k}`"));
                    }
                    Some(a @ Value::Object(_)) => check(root, a, x, &sub)?,
                    _ => {}
                },
            }
        }
    }
    if let (Some(items), Some(arr)) = (s.get("items"), v.as_array()) {
        for (i, x) in arr.iter().enumerate() {
            check(root, items, x, &format!("{path}[{i}]"))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_checker_catches_each_kind_of_problem() {
        let schema = json!({
            "type": "object",
            "required": ["a"],
            "additionalProperties": false,
            "properties": {
                "a": {"type": "array", "items": {"$ref": "#/$defs/n"}},
                "b": {"type": ["string", "null"]}
            },
            "$defs": {"n": {"type": "integer", "minimum": 1}}
        });
        assert!(validate(&schema, &json!({"a": [1, 2], "b": null})).is_ok());
        for bad in [
            json!({"b": "x"}),
            json!({"a": [1, 0]}),
            json!({"a": [1.5]}),
            json!({"a": [], "b": 3}),
            json!({"a": [], "c": 1}),
            json!([1]),
        ] {
            assert!(validate(&schema, &bad).is_err(), "{bad} passed");
        }
    }

    #[test]
    fn the_shipped_schema_parses() {
        let s: Value = serde_json::from_str(SCHEMA).unwrap();
        assert_eq!(s["type"], "object");
    }
}
