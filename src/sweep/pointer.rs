//! Writing a value at a JSON pointer (RFC 6901) of a sweep's inputs.
//!
//! Missing object members along the way are created (as objects, then the value), so an
//! axis may set an input the base leaves to its default (`/reference/modes`); array
//! elements must already exist, and nothing but an object or an array can be entered.

use serde_json::Value;

/// The unescaped reference tokens of `pointer` (`~1` is `/`, `~0` is `~`).
pub fn tokens(pointer: &str) -> Result<Vec<String>, String> {
    if pointer.is_empty() {
        return Err("must point into the inputs, not be the empty pointer".into());
    }
    let Some(rest) = pointer.strip_prefix('/') else {
        return Err(format!(
            "`{pointer}` is not a JSON pointer (it must start with `/`)"
        ));
    };
    Ok(rest
        .split('/')
        .map(|t| t.replace("~1", "/").replace("~0", "~"))
        .collect())
}

/// Sets `value` at `pointer` in `document`; the error says why it cannot.
pub fn set(document: &mut Value, pointer: &str, value: Value) -> Result<(), String> {
    let tokens = tokens(pointer)?;
    let mut target = document;
    let last = tokens.len() - 1;
    for (depth, token) in tokens.iter().enumerate() {
        let at = |depth: usize| format!("/{}", tokens[..depth].join("/"));
        target = match target {
            Value::Object(map) => {
                if depth == last {
                    map.insert(token.clone(), value);
                    return Ok(());
                }
                map.entry(token.clone())
                    .or_insert_with(|| Value::Object(Default::default()))
            }
            Value::Array(items) => {
                let index: usize = token
                    .parse()
                    .map_err(|_| format!("`{token}` is not an index of the array at `{}`", at(depth)))?;
                let length = items.len();
                let item = items.get_mut(index).ok_or_else(|| {
                    format!(
                        "the array at `{}` has {length} elements, no element {index}",
                        at(depth)
                    )
                })?;
                if depth == last {
                    *item = value;
                    return Ok(());
                }
                item
            }
            other => {
                return Err(format!(
                    "`{}` is a {}, which has no member `{token}`",
                    at(depth),
                    kind(other)
                ));
            }
        };
    }
    unreachable!("the last token returns")
}

fn kind(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn values_are_set_and_missing_members_created() {
        let mut doc = json!({"contact": {"rk": 1.0}, "list": [1, 2]});
        set(&mut doc, "/contact/rk", json!(10.0)).unwrap();
        set(&mut doc, "/reference/modes", json!(5)).unwrap();
        set(&mut doc, "/list/1", json!(7)).unwrap();
        assert_eq!(
            doc,
            json!({"contact": {"rk": 10.0}, "reference": {"modes": 5}, "list": [1, 7]})
        );
    }

    #[test]
    fn impossible_pointers_say_why() {
        let mut doc = json!({"contact": {"rk": 1.0}, "list": [1]});
        assert!(
            set(&mut doc, "/contact/rk/x", json!(1))
                .unwrap_err()
                .contains("number")
        );
        assert!(
            set(&mut doc, "/list/3", json!(1))
                .unwrap_err()
                .contains("no element 3")
        );
        assert!(set(&mut doc, "contact", json!(1)).is_err());
        assert!(set(&mut doc, "", json!(1)).is_err());
    }
}
