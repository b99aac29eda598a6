//! Getting the JSON out of what a model wrote.

use serde::de::DeserializeOwned;

/// The longest content [`parse_json_content`] looks at, in bytes: a plan is a few KiB, and
/// scanning megabytes of prose for braces would only waste time.
pub const MAX_JSON_CONTENT_BYTES: usize = 256 * 1024;

/// The longest error message [`parse_json_content`] returns, in characters, so that sending it
/// back to the model costs few tokens.
const MAX_ERROR_CHARS: usize = 300;

/// Parses the JSON value in a model's reply as `T`.
///
/// Models asked for JSON often wrap it anyway: in a ```` ```json ```` fence, after "Here is the
/// plan:", before a closing remark, or after a `<think>…</think>` block. This tries, in order,
/// the whole content, each fenced block, and the first balanced `{…}` or `[…]` in what is left
/// after removing think blocks. Schema validation beyond what `T`'s `Deserialize` checks is
/// the caller's job.
///
/// The error is a short message meant to be sent back to the model in a retry, e.g. "your
/// reply is not valid JSON (expected `,` or `}` at line 1 column 9); reply with only the JSON
/// value".
pub fn parse_json_content<T: DeserializeOwned>(content: &str) -> Result<T, String> {
    if content.len() > MAX_JSON_CONTENT_BYTES {
        return Err(format!(
            "your reply is {} bytes long, over the limit of {MAX_JSON_CONTENT_BYTES}; reply with \
             only the JSON value, without commentary",
            content.len()
        ));
    }
    let content = content.trim_start_matches('\u{feff}').trim();
    if content.is_empty() {
        return Err("your reply is empty; reply with only the JSON value".to_string());
    }
    // Candidates go from the whole content to ever more targeted slices of it, so the last
    // error of each kind is the most specific. A shape error (valid JSON, wrong fields) is
    // the useful one when there is one: it tells the model which field to fix.
    let mut shape_error: Option<serde_json::Error> = None;
    let mut syntax_error: Option<serde_json::Error> = None;
    let without_thoughts = strip_think_blocks(content);
    let candidates = std::iter::once(content)
        .chain(fenced_blocks(content))
        .chain(balanced_value(&without_thoughts));
    for candidate in candidates {
        match serde_json::from_str::<T>(candidate) {
            Ok(value) => return Ok(value),
            Err(e) if e.is_data() => shape_error = Some(e),
            Err(e) => syntax_error = Some(e),
        }
    }
    let message = match (shape_error, syntax_error) {
        (Some(e), _) => format!(
            "your reply does not match the required JSON schema ({e}); reply with only the \
             corrected JSON value"
        ),
        (None, Some(e)) if !without_thoughts.contains(['{', '[']) => {
            format!("your reply contains no JSON value ({e}); reply with only the JSON value")
        }
        (None, Some(e)) if e.is_eof() => {
            format!("your reply is cut off ({e}); reply with a shorter, complete JSON value")
        }
        (None, Some(e)) => format!(
            "your reply is not valid JSON ({e}); reply with only the JSON value, without \
             comments or trailing commas"
        ),
        (None, None) => "your reply contains no JSON value; reply with only the JSON value".into(),
    };
    Err(cap_chars(&message, MAX_ERROR_CHARS))
}

fn cap_chars(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text.to_string(),
    }
}

/// The insides of ```` ``` ```` fences, language tag (```` ```json ````) dropped.
fn fenced_blocks(text: &str) -> impl Iterator<Item = &str> {
    text.split("```")
        .skip(1)
        .step_by(2)
        .map(|block| {
            // A language tag is the rest of the opening line when it is one bare word.
            match block.split_once('\n') {
                Some((tag, rest)) if !tag.trim().contains([' ', '{', '[']) => rest,
                _ => block,
            }
            .trim()
        })
        .filter(|block| !block.is_empty())
}

/// `text` without `<think>…</think>` blocks (reasoning models emit them before the answer; an
/// unclosed one swallows the rest).
fn strip_think_blocks(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find("<think>") {
        out.push_str(&rest[..start]);
        match rest[start..].find("</think>") {
            Some(end) => rest = &rest[start + end + "</think>".len()..],
            None => return out,
        }
    }
    out.push_str(rest);
    out
}

/// The first balanced `{…}` or `[…]` in `text`, brackets inside strings ignored.
fn balanced_value(text: &str) -> Option<&str> {
    let start = text.find(['{', '['])?;
    let mut depth = 0usize;
    let mut in_string = false;
    let mut escaped = false;
    for (i, c) in text[start..].char_indices() {
        if in_string {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                '"' => in_string = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_string = true,
            '{' | '[' => depth += 1,
            '}' | ']' => {
                depth -= 1;
                if depth == 0 {
                    return Some(&text[start..start + i + 1]);
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, Deserialize, PartialEq)]
    struct Plan {
        segments: Vec<String>,
    }

    fn plan(names: &[&str]) -> Plan {
        Plan {
            segments: names.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn finds_the_json_in_what_models_write() {
        let cases = [
            r#"{"segments": ["walk"]}"#,
            "```json\n{\"segments\": [\"walk\"]}\n```",
            "```\n{\"segments\": [\"walk\"]}\n```",
            "Here is the plan:\n```json\n{\"segments\": [\"walk\"]}\n```\nEnjoy!",
            "Sure! {\"segments\": [\"walk\"]} Let me know if you need more.",
            "<think>maybe {\"segments\": []}?</think>\n{\"segments\": [\"walk\"]}",
            "\u{feff}  {\"segments\": [\"walk\"]}  ",
        ];
        for case in cases {
            assert_eq!(
                parse_json_content::<Plan>(case),
                Ok(plan(&["walk"])),
                "{case:?}"
            );
        }
        // Braces inside strings do not end the value early.
        assert_eq!(
            parse_json_content::<Plan>(r#"Plan: {"segments": ["wave }{ hand"]} done"#),
            Ok(plan(&["wave }{ hand"]))
        );
    }

    #[test]
    fn errors_are_short_and_say_what_to_fix() {
        let e = parse_json_content::<Plan>(r#"{"segments": "walk"}"#).unwrap_err();
        assert!(
            e.starts_with("your reply does not match the required JSON schema"),
            "{e}"
        );
        let e = parse_json_content::<Plan>(r#"{"segments": ["walk",]}"#).unwrap_err();
        assert!(e.starts_with("your reply is not valid JSON"), "{e}");
        let e = parse_json_content::<Plan>("Plan: ```json\n{\"segments\": [\"wa").unwrap_err();
        assert!(e.starts_with("your reply is cut off"), "{e}");
        let e = parse_json_content::<Plan>("I cannot help with that.").unwrap_err();
        assert!(e.starts_with("your reply contains no JSON value"), "{e}");
        let e = parse_json_content::<Plan>("   ").unwrap_err();
        assert!(e.starts_with("your reply is empty"), "{e}");
        let huge = format!(
            "{{\"segments\": [\"{}\"]}}",
            "a".repeat(MAX_JSON_CONTENT_BYTES)
        );
        let e = parse_json_content::<Plan>(&huge).unwrap_err();
        assert!(e.contains("over the limit"), "{e}");
        let long_field = format!("{{\"segments\": [{}]}}", "1,".repeat(2000) + "1");
        let e = parse_json_content::<Plan>(&long_field).unwrap_err();
        assert!(e.chars().count() <= MAX_ERROR_CHARS + 1, "{e}");
    }
}
