//! Walking a JSON schema alongside a JSON value: every member the schema describes at
//! every object the value holds (present or not), with its schema resolved to the
//! alternative the value takes (`oneOf`/`anyOf`: the tagged object whose `type` it
//! names, or the JSON type it has; `allOf`: the parts merged).
//!
//! Each member is located twice: by its JSON pointer in the value, and by its place
//! in the schema (`bundle/gaps<random>/distribution<normal>/std`: member names, and
//! the alternative taken where there is a choice, `*` for a list's items), which
//! [`locations`] lists for the whole schema so that a test can tell which places no
//! example reached.

use serde_json::{Map, Value};

/// One member of an object of the value, as the schema describes it.
#[derive(Debug, Clone)]
pub struct Site {
    /// JSON pointer of the member in the walked value.
    pub pointer: String,
    /// Its place in the schema (see the module documentation).
    pub location: String,
    /// The member's place, whichever alternative its value takes (where its default is).
    pub member: String,
    /// Its schema, the alternative its value takes chosen (the alternatives left when it
    /// is absent and they are several).
    pub schema: Value,
    /// Whether the value has the member.
    pub present: bool,
    /// The member's description (a list's, for its items).
    pub description: String,
}

/// Keywords that combine schemas rather than describe a value.
const COMBINATORS: [&str; 3] = ["oneOf", "anyOf", "allOf"];

/// The JSON types a schema allows (`type` as a string or a list).
pub fn types(schema: &Value) -> Vec<&str> {
    match &schema["type"] {
        Value::String(kind) => vec![kind.as_str()],
        Value::Array(kinds) => kinds.iter().filter_map(Value::as_str).collect(),
        _ if schema["properties"].is_object() => vec!["object"],
        _ => vec![],
    }
}

/// `schema` with its `allOf` parts merged into one (properties and required members
/// united; the schema's own keywords win).
fn merged(schema: &Value) -> Value {
    let Some(parts) = schema["allOf"].as_array() else {
        return schema.clone();
    };
    let mut out = Map::new();
    let mut properties = Map::new();
    let mut required = Vec::new();
    for part in parts.iter().map(merged) {
        for (key, value) in part.as_object().into_iter().flatten() {
            match key.as_str() {
                "properties" => properties.extend(value.as_object().cloned().unwrap_or_default()),
                "required" => required.extend(value.as_array().cloned().unwrap_or_default()),
                _ => {
                    out.insert(key.clone(), value.clone());
                }
            }
        }
    }
    for (key, value) in schema.as_object().into_iter().flatten() {
        if key != "allOf" {
            out.insert(key.clone(), value.clone());
        }
    }
    if !properties.is_empty() {
        out.insert("properties".into(), Value::Object(properties));
        out.insert("type".into(), "object".into());
    }
    if !required.is_empty() {
        out.insert("required".into(), Value::Array(required));
    }
    Value::Object(out)
}

/// The name of an alternative: the tag its `type` member takes, else its JSON type.
fn tag(alternative: &Value) -> String {
    if let Some([tag]) = alternative["properties"]["type"]["enum"]
        .as_array()
        .map(Vec::as_slice)
    {
        return tag.as_str().unwrap_or_default().to_owned();
    }
    types(alternative)
        .into_iter()
        .find(|t| *t != "null")
        .unwrap_or("any")
        .to_owned()
}

/// Whether `value` is an instance of the alternative `schema` (its tag or JSON type).
fn matches(schema: &Value, value: &Value) -> bool {
    if let (Some(tag), Some(names)) = (
        value.get("type").and_then(Value::as_str),
        schema["properties"]["type"]["enum"].as_array(),
    ) {
        return names.iter().any(|n| n == tag);
    }
    let kinds = types(schema);
    let kind = match value {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(n) if n.is_f64() => "number",
        Value::Number(_) if kinds.contains(&"integer") => "integer",
        Value::Number(_) => "number",
        Value::String(s) => {
            return kinds.contains(&"string")
                && schema["enum"]
                    .as_array()
                    .is_none_or(|names| names.iter().any(|n| n == s));
        }
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    };
    kinds.contains(&kind)
}

/// The alternatives of `schema` (itself when it offers none), each merged; `null`
/// alternatives left out.
fn options(schema: &Value) -> Vec<Value> {
    let schema = merged(schema);
    let Some(options) = schema["oneOf"].as_array().or(schema["anyOf"].as_array()) else {
        return vec![schema];
    };
    options
        .iter()
        .flat_map(self::options)
        .filter(|option| types(option) != ["null"])
        .collect()
}

/// The keywords written beside a choice (a member's description, default).
fn beside(schema: &Value) -> Value {
    let mut out = merged(schema);
    if let Some(map) = out.as_object_mut() {
        map.retain(|key, _| !COMBINATORS.contains(&key.as_str()));
    }
    out
}

/// [`options`], each with the keywords written beside the choice.
pub fn alternatives(schema: &Value) -> Vec<Value> {
    let outer = beside(schema);
    options(schema)
        .into_iter()
        .map(|mut option| {
            for (key, value) in outer.as_object().into_iter().flatten() {
                option[key] = value.clone();
            }
            option
        })
        .collect()
}

/// The schema of a member whose value is `value` (`None`: absent), and the suffix of its
/// location naming the alternative taken (empty without a choice).
pub fn resolve(schema: &Value, value: Option<&Value>) -> (Value, String) {
    let options = alternatives(schema);
    if options.len() == 1 {
        return (options[0].clone(), String::new());
    }
    match value.and_then(|v| options.iter().find(|o| matches(o, v))) {
        Some(chosen) => (chosen.clone(), format!("<{}>", tag(chosen))),
        None => (merged(schema), String::new()),
    }
}

fn escape(name: &str) -> String {
    name.replace('~', "~0").replace('/', "~1")
}

/// Every member of every object of `value` (at `pointer`, its schema `schema`, at
/// `location`), present or not, depth first (a list's items share one location).
pub fn sites(schema: &Value, value: &Value, pointer: &str, location: &str, out: &mut Vec<Site>) {
    let (schema, _) = resolve(schema, Some(value));
    match value {
        Value::Object(members) => {
            let Some(properties) = schema["properties"].as_object() else {
                return;
            };
            for (name, property) in properties {
                let member = members.get(name);
                let (resolved, choice) = resolve(property, member);
                let site = Site {
                    pointer: format!("{pointer}/{}", escape(name)),
                    location: format!("{location}/{name}{choice}"),
                    member: format!("{location}/{name}"),
                    description: resolved["description"].as_str().unwrap_or_default().to_owned(),
                    schema: resolved,
                    present: member.is_some(),
                };
                if let Some(member) = member {
                    sites(&site.schema, member, &site.pointer, &site.location, out);
                }
                out.push(site);
            }
        }
        Value::Array(items) => {
            for (index, item) in items.iter().enumerate() {
                let (item_schema, choice) = resolve(&schema["items"], Some(item));
                let site = Site {
                    pointer: format!("{pointer}/{index}"),
                    location: format!("{location}/*{choice}"),
                    member: format!("{location}/*"),
                    schema: item_schema,
                    present: true,
                    description: schema["description"].as_str().unwrap_or_default().to_owned(),
                };
                sites(&site.schema, item, &site.pointer, &site.location, out);
                out.push(site);
            }
        }
        _ => {}
    }
}

/// A place of a schema: a member (or a list's items), or one alternative of it.
#[derive(Debug, Clone)]
pub struct Place {
    pub location: String,
    pub schema: Value,
    /// Whether this is one alternative of a member that offers several (its description
    /// and default are the member's).
    pub alternative: bool,
}

fn push_place(location: String, schema: &Value, out: &mut Vec<Place>) {
    let choices = options(schema);
    if choices.len() == 1 {
        out.push(Place {
            location,
            schema: alternatives(schema).remove(0),
            alternative: false,
        });
        return;
    }
    for choice in choices {
        out.push(Place {
            location: format!("{location}<{}>", tag(&choice)),
            schema: choice,
            alternative: true,
        });
    }
    out.push(Place {
        location,
        schema: beside(schema),
        alternative: false,
    });
}

/// Every place of `schema` (at `location`): members of objects, items of lists, through
/// every alternative.
pub fn locations(schema: &Value, location: &str, out: &mut Vec<Place>) {
    let choices = options(schema);
    let several = choices.len() > 1;
    for option in &choices {
        let here = match several {
            true => format!("{location}<{}>", tag(option)),
            false => location.to_owned(),
        };
        if let Some(properties) = option["properties"].as_object() {
            for (name, property) in properties {
                let member = format!("{here}/{name}");
                push_place(member.clone(), property, out);
                locations(property, &member, out);
            }
        }
        if let Some(items) = option.get("items") {
            let location = format!("{here}/*");
            push_place(location.clone(), items, out);
            locations(items, &location, out);
        }
    }
}

/// `value` with the member at `pointer` (relative to it) set, created in its parent
/// object when absent.
pub fn with(value: &Value, pointer: &str, member: Value) -> Value {
    let mut out = value.clone();
    let (parent, name) = pointer.rsplit_once('/').expect("a member's pointer");
    let name = name.replace("~1", "/").replace("~0", "~");
    match out.pointer_mut(parent) {
        Some(Value::Object(map)) => {
            map.insert(name, member);
        }
        Some(Value::Array(items)) => {
            let index: usize = name.parse().expect("an index");
            items[index] = member;
        }
        _ => panic!("no object at {parent} to set {pointer} in"),
    }
    out
}

/// `value` without the member at `pointer`.
pub fn without(value: &Value, pointer: &str) -> Value {
    let mut out = value.clone();
    let (parent, name) = pointer.rsplit_once('/').expect("a member's pointer");
    let name = name.replace("~1", "/").replace("~0", "~");
    if let Some(Value::Object(map)) = out.pointer_mut(parent) {
        map.remove(&name);
    }
    out
}

/// `schema` with its references to `components` (an OpenAPI document's schemas)
/// inlined, as the process descriptions serve theirs.
pub fn inlined(schema: &Value, components: &Value) -> Value {
    match schema {
        Value::Object(map) => {
            if let Some(name) = map
                .get("$ref")
                .and_then(Value::as_str)
                .and_then(|r| r.strip_prefix("#/components/schemas/"))
            {
                let mut component = inlined(&components[name], components);
                for (key, value) in map.iter().filter(|(key, _)| *key != "$ref") {
                    component[key] = inlined(value, components);
                }
                return component;
            }
            Value::Object(
                map.iter()
                    .map(|(key, value)| (key.clone(), inlined(value, components)))
                    .collect(),
            )
        }
        Value::Array(items) => Value::Array(items.iter().map(|v| inlined(v, components)).collect()),
        other => other.clone(),
    }
}
