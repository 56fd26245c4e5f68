//! A member of a JSON object as it was given: missing, read as its type, or of another
//! type (kept as written).
//!
//! serde stops at the first member of the wrong type; a sweep request reports every
//! problem at once, each with its own pointer and wording. Its members are therefore
//! read as [`Member`]s: deserializing never fails on a member's type, and the checks
//! that follow ([`super::spec`]) name each mistyped member. For the OpenAPI schema a
//! `Member<T>` field is declared as `T` (`#[schema(value_type = T)]`).

use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::Value;

/// One member of a JSON object, as given.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Member<T> {
    /// Not in the object (the field's `#[serde(default)]`).
    #[default]
    Missing,
    /// Present and of type `T`.
    Typed(T),
    /// Present but not a `T` (`null` included): the JSON as written.
    Mistyped(Value),
}

impl<T> Member<T> {
    pub fn is_missing(&self) -> bool {
        matches!(self, Member::Missing)
    }

    /// The value when it has its type.
    pub fn typed(&self) -> Option<&T> {
        match self {
            Member::Typed(value) => Some(value),
            Member::Missing | Member::Mistyped(_) => None,
        }
    }
}

impl<'de, T: DeserializeOwned> Deserialize<'de> for Member<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let value = Value::deserialize(deserializer)?;
        Ok(match T::deserialize(&value) {
            Ok(typed) => Member::Typed(typed),
            Err(_) => Member::Mistyped(value),
        })
    }
}

impl<T: Serialize> Serialize for Member<T> {
    /// As given (`null` when missing: fields skip missing members with
    /// `skip_serializing_if = "Member::is_missing"`).
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Member::Missing => serializer.serialize_unit(),
            Member::Typed(value) => value.serialize(serializer),
            Member::Mistyped(value) => value.serialize(serializer),
        }
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    #[derive(Debug, Deserialize, Serialize)]
    struct Holder {
        #[serde(default, skip_serializing_if = "Member::is_missing")]
        count: Member<u64>,
        #[serde(default, skip_serializing_if = "Member::is_missing")]
        name: Member<String>,
    }

    #[test]
    fn a_member_is_missing_typed_or_mistyped_and_never_fails_its_object() {
        let holder: Holder = serde_json::from_value(json!({"count": 2.5})).unwrap();
        assert_eq!(holder.count, Member::Mistyped(json!(2.5)));
        assert_eq!(holder.name, Member::Missing);
        let holder: Holder = serde_json::from_value(json!({"count": 3, "name": null})).unwrap();
        assert_eq!(holder.count, Member::Typed(3));
        assert_eq!(holder.name, Member::Mistyped(Value::Null));
    }

    #[test]
    fn a_member_serializes_as_given() {
        let given = json!({"count": -1, "name": "x"});
        let holder: Holder = serde_json::from_value(given.clone()).unwrap();
        assert_eq!(serde_json::to_value(&holder).unwrap(), given);
        let holder: Holder = serde_json::from_value(json!({})).unwrap();
        assert_eq!(serde_json::to_value(&holder).unwrap(), json!({}));
    }
}
