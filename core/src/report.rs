//! Text that stays valid whatever the names in it: CSV fields quoted as RFC
//! 4180 says, JSON strings escaped as RFC 8259 says. Every CSV and JSON
//! heliodon writes goes through these.

use std::borrow::Cow;

/// A CSV field: as it is when it can be, else in double quotes with its
/// quotes doubled (a name with a comma, a quote or a line break).
pub fn csv_field(text: &str) -> Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) { Cow::Owned(format!("\"{}\"", text.replace('"', "\"\""))) } else { Cow::Borrowed(text) }
}

/// A JSON string literal, quotes included: `"`, `\` and control characters escaped.
pub fn json_string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_and_strings_survive_any_name() {
        assert_eq!(csv_field("desk-1"), "desk-1");
        assert_eq!(csv_field("desk, north"), "\"desk, north\"");
        assert_eq!(csv_field("the \"big\" desk"), "\"the \"\"big\"\" desk\"");
        assert_eq!(csv_field("two\nlines"), "\"two\nlines\"");
        assert_eq!(json_string("a\"b\\c"), r#""a\"b\\c""#);
        assert_eq!(json_string("bell\u{7}\ttab\nline"), r#""bell\u0007\ttab\nline""#);
        assert_eq!(json_string("é ☀"), "\"é ☀\"");
    }
}
