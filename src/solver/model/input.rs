//! Reading the JSON a client writes, strictly: one object, no key twice in any object, a
//! section only from an object, and whatever an error quotes back from the client clipped to
//! [`ECHO_CHARS`]. serde_json alone keeps the last of two equal keys and reads a struct from an
//! array by position; these readers refuse both and say where.

use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use serde_json::{Map, Value};
use std::borrow::Cow;
use std::fmt;
use std::marker::PhantomData;

/// Longest piece of client text (a field name, a value) an error quotes back, characters.
pub const ECHO_CHARS: usize = 100;

/// Why a text is not a JSON object: where (a dotted path, clipped; `None` at the top) and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JsonError {
    pub field: Option<String>,
    pub message: String,
}

/// The one JSON object in `text`, with nothing after it and no key twice in any object, as a
/// `serde_json` map. A repeated key is named by its path (`tube.length_mm`).
pub fn object_from_str(text: &str) -> Result<Map<String, Value>, JsonError> {
    if !text.trim_start().starts_with('{') {
        return Err(JsonError {
            field: None,
            message: "must be a JSON object".into(),
        });
    }
    let mut path = Vec::new();
    let mut de = serde_json::Deserializer::from_str(text);
    let read = Strict { path: &mut path }
        .deserialize(&mut de)
        .and_then(|value| de.end().map(|()| value));
    match read {
        Ok(Value::Object(map)) => Ok(map),
        Ok(_) => unreachable!("the text starts with an object"),
        Err(e) => Err(JsonError {
            field: (!path.is_empty()).then(|| clip(&path.join(".")).into_owned()),
            message: clip_quoted(&e.to_string()),
        }),
    }
}

/// Builds a [`Value`] as serde_json does, but fails on a key seen before in the same object.
/// `path` holds where it is; after a failure, where the failure is.
struct Strict<'p> {
    path: &'p mut Vec<String>,
}

impl<'de> DeserializeSeed<'de> for Strict<'_> {
    type Value = Value;

    fn deserialize<D: Deserializer<'de>>(self, de: D) -> Result<Value, D::Error> {
        de.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Strict<'_> {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }

    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        loop {
            self.path.push(out.len().to_string());
            let next = seq.next_element_seed(Strict {
                path: &mut *self.path,
            })?;
            self.path.pop();
            match next {
                Some(v) => out.push(v),
                None => return Ok(Value::Array(out)),
            }
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let repeated = out.contains_key(&key);
            self.path.push(key);
            if repeated {
                return Err(de::Error::custom("the key is given more than once"));
            }
            let value = map.next_value_seed(Strict {
                path: &mut *self.path,
            })?;
            let key = self.path.pop().unwrap_or_default();
            out.insert(key, value);
        }
        Ok(Value::Object(out))
    }
}

/// `#[serde(deserialize_with = "object")]` for a section of a case: read only from a JSON
/// object (by name), never from an array (which serde would read by position).
pub fn object<'de, D, T>(de: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    struct ObjectOnly<T>(PhantomData<T>);

    impl<'de, T: Deserialize<'de>> Visitor<'de> for ObjectOnly<T> {
        type Value = T;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("an object")
        }

        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
            T::deserialize(de::value::MapAccessDeserializer::new(map))
        }
    }

    de.deserialize_map(ObjectOnly(PhantomData))
}

/// serde's message about a client's JSON in the client's words, its quotes clipped
/// ([`clip_quoted`]): "expected a number" for "expected f64", "got the text \"abc\"" for
/// "invalid type: string \"abc\"", "a list" for "a sequence" ([`in_user_words`]).
pub fn user_message(serde_message: &str) -> String {
    in_user_words(&clip_quoted(serde_message))
}

/// The Rust words of a serde message replaced by a JSON writer's: the type names after
/// "expected" and "invalid type/value" said as what a JSON value is.
pub fn in_user_words(message: &str) -> String {
    const GOT: &[(&str, &str)] = &[
        ("invalid type: string ", "got the text "),
        ("invalid type: integer ", "got the whole number "),
        ("invalid type: floating point ", "got the number "),
        ("invalid type: boolean ", "got "),
        ("invalid type: null", "got null"),
        ("invalid type: sequence", "got a list"),
        ("invalid type: map", "got an object"),
        ("invalid value: integer ", "got "),
        ("invalid value: floating point ", "got "),
        ("invalid value: string ", "got the text "),
    ];
    let mut out = message.to_string();
    for (rust, user) in GOT {
        out = out.replace(rust, user);
    }
    // "expected <type>": the type is one word (u32) or "struct Name", up to a comma, a space
    // or the end.
    let mut said = String::with_capacity(out.len());
    let mut rest = out.as_str();
    while let Some(at) = rest.find("expected ") {
        let (before, after) = rest.split_at(at + "expected ".len());
        said.push_str(before);
        let word_end = after.find([',', ' ', ')']).unwrap_or(after.len());
        let (word, tail) = after.split_at(word_end);
        let (user, tail) = match word {
            "f64" | "f32" => ("a number", tail),
            "u8" | "u16" | "u32" | "u64" | "u128" | "usize" => ("a whole number, 0 or more", tail),
            "i8" | "i16" | "i32" | "i64" | "i128" | "isize" => ("a whole number", tail),
            "struct" => {
                let name_end = tail[1..]
                    .find([',', ' ', ')'])
                    .map_or(tail.len(), |i| i + 1);
                ("an object", &tail[name_end..])
            }
            "a" if tail.starts_with(" sequence") => ("a list", &tail[" sequence".len()..]),
            "a" if tail.starts_with(" map") => ("an object", &tail[" map".len()..]),
            _ => (word, tail),
        };
        said.push_str(user);
        rest = tail;
    }
    said.push_str(rest);
    said
}

/// `text` cut to [`ECHO_CHARS`] characters, with "…" where it was cut.
pub fn clip(text: &str) -> Cow<'_, str> {
    match text.char_indices().nth(ECHO_CHARS) {
        None => Cow::Borrowed(text),
        Some((end, _)) => Cow::Owned(format!("{}…", &text[..end])),
    }
}

/// A message (serde's, which quotes client text in backticks or as a Rust string literal) with
/// every quoted piece clipped to [`ECHO_CHARS`].
pub fn clip_quoted(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(1024));
    let mut rest = message;
    while let Some(open) = rest.find(['`', '"']) {
        let quote = rest.as_bytes()[open] as char;
        out.push_str(&rest[..=open]);
        let inner = &rest[open + 1..];
        let close = quoted_len(inner, quote);
        out.push_str(&clip(&inner[..close]));
        rest = &inner[close..];
        if let Some(after) = rest.strip_prefix(quote) {
            out.push(quote);
            rest = after;
        }
    }
    out.push_str(rest);
    out
}

/// Bytes of `text` before its closing `quote` (all of it if unclosed); in a string literal a
/// backslash escapes the character after it.
fn quoted_len(text: &str, quote: char) -> usize {
    let mut escaped = false;
    for (i, c) in text.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' if quote == '"' => escaped = true,
            c if c == quote => return i,
            _ => {}
        }
    }
    text.len()
}

/// Sets the field at a dotted `path` of a case's JSON (`"tube.length_mm"`), making the sections
/// on the way. When a step of the path holds something other than an object, nothing is set
/// and the error is the path walked to it (empty: `case` itself is not an object).
pub fn set_field(case: &mut Value, path: &str, value: Value) -> Result<(), String> {
    let mut node = case;
    let mut walked = Vec::new();
    let segments: Vec<&str> = path.split('.').collect();
    for (i, segment) in segments.iter().enumerate() {
        let Some(object) = node.as_object_mut() else {
            return Err(walked.join("."));
        };
        if i + 1 == segments.len() {
            object.insert(segment.to_string(), value);
            return Ok(());
        }
        walked.push(*segment);
        node = object
            .entry(segment.to_string())
            .or_insert_with(|| Value::Object(Map::new()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {

    #[test]
    fn serde_s_rust_words_become_json_words() {
        for (serde, user) in [
            (
                r#"invalid type: string "abc", expected f64"#,
                r#"got the text "abc", expected a number"#,
            ),
            (
                "invalid type: floating point `2.5`, expected u32",
                "got the number `2.5`, expected a whole number, 0 or more",
            ),
            (
                "invalid value: integer `-1`, expected u64",
                "got `-1`, expected a whole number, 0 or more",
            ),
            (
                "invalid type: map, expected a sequence",
                "got an object, expected a list",
            ),
            (
                "invalid type: sequence, expected struct TubeSpec",
                "got a list, expected an object",
            ),
            (
                "invalid type: null, expected a boolean",
                "got null, expected a boolean",
            ),
            (
                "unknown field `x`, expected one of `a`, `b`",
                "unknown field `x`, expected one of `a`, `b`",
            ),
        ] {
            assert_eq!(in_user_words(serde), user);
        }
    }

    use super::*;
    use serde_json::json;

    #[test]
    fn a_key_given_twice_is_refused_with_its_path() {
        let cases = [
            (r#"{"a": 1, "a": 2}"#, "a"),
            (
                r#"{"tube": {"length_mm": 8, "length_mm": 9}}"#,
                "tube.length_mm",
            ),
            (r#"{"p": {"x.y": [1], "x.y": [2]}}"#, "p.x.y"),
            (r#"{"l": [{}, {"k": 1, "k": 1}]}"#, "l.1.k"),
        ];
        for (text, field) in cases {
            let e = object_from_str(text).unwrap_err();
            assert_eq!(e.field.as_deref(), Some(field), "{text}");
            assert!(e.message.contains("more than once"), "{e:?}");
        }
    }

    #[test]
    fn a_strict_read_is_what_serde_json_reads_when_no_key_repeats() {
        let text = r#"{"a": [1, -2, 3.5, 500.0, 18446744073709551615, true, null, "s"],
                       "b": {"c": {}, "d": []}, "e": -0}"#;
        let strict = Value::Object(object_from_str(text).unwrap());
        let loose: Value = serde_json::from_str(text).unwrap();
        assert_eq!(strict, loose);
        assert_eq!(strict.to_string(), loose.to_string());
    }

    #[test]
    fn only_one_object_is_read() {
        for text in [
            "[]",
            "3",
            "null",
            "\"{}\"",
            "{} x",
            "{}{}",
            "{",
            r#"{"a": }"#,
        ] {
            assert!(object_from_str(text).is_err(), "{text}");
        }
        assert!(object_from_str(" {}\n").unwrap().is_empty());
    }

    #[test]
    fn a_section_is_read_from_an_object_only() {
        #[derive(Debug, Default, serde::Deserialize)]
        #[serde(default)]
        struct Inner {
            a: u32,
            b: bool,
        }
        #[derive(Debug, serde::Deserialize)]
        struct Outer {
            #[serde(deserialize_with = "object")]
            inner: Inner,
        }
        let ok: Outer = serde_json::from_value(json!({"inner": {"a": 3}})).unwrap();
        assert_eq!((ok.inner.a, ok.inner.b), (3, false));
        let text = r#"{"inner": [3, true]}"#;
        let de = &mut serde_json::Deserializer::from_str(text);
        let e = serde_path_to_error::deserialize::<_, Outer>(de).unwrap_err();
        assert_eq!(e.path().to_string(), "inner");
        assert!(e.inner().to_string().contains("expected an object"), "{e}");
        // The path goes on inside the section.
        let text = r#"{"inner": {"a": "x"}}"#;
        let de = &mut serde_json::Deserializer::from_str(text);
        let e = serde_path_to_error::deserialize::<_, Outer>(de).unwrap_err();
        assert_eq!(e.path().to_string(), "inner.a");
    }

    #[test]
    fn long_client_text_is_clipped_in_errors() {
        let long = "a".repeat(200_000);
        assert_eq!(clip(&long).chars().count(), ECHO_CHARS + 1);
        assert!(clip(&long).ends_with('…'));
        assert_eq!(clip("short"), "short");
        // Multi-byte characters are cut between characters.
        assert_eq!(clip(&"é".repeat(101)).chars().count(), ECHO_CHARS + 1);
        let message = format!("unknown field `{long}`, expected one of `tube`, `label`");
        let clipped = clip_quoted(&message);
        assert!(clipped.len() < 200, "{clipped}");
        assert!(
            clipped.ends_with("…`, expected one of `tube`, `label`"),
            "{clipped}"
        );
        let message = format!(r#"invalid type: string "{long}\"{long}", expected f64"#);
        let clipped = clip_quoted(&message);
        assert!(clipped.ends_with("…\", expected f64"), "{clipped}");
        let text = format!(r#"{{"{long}": 1, "{long}": 2}}"#);
        let e = object_from_str(&text).unwrap_err();
        assert_eq!(e.field.unwrap().chars().count(), ECHO_CHARS + 1);
        // Unclosed quotes are clipped to the end.
        assert_eq!(
            clip_quoted(&format!("`{long}")).chars().count(),
            ECHO_CHARS + 2
        );
    }
}
