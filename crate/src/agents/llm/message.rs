//! What is sent: the conversation, the reply format and the sampling options.

use base64::Engine as _;
use serde_json::{json, Value};

/// Who says a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Instructions for the model.
    System,
    /// The user's turn (the prompt, a validation error to fix, images to describe).
    User,
    /// An earlier reply of the model, e.g. the invalid one a retry asks it to correct.
    Assistant,
}

impl Role {
    /// The role's name in the API.
    pub fn as_str(self) -> &'static str {
        match self {
            Role::System => "system",
            Role::User => "user",
            Role::Assistant => "assistant",
        }
    }
}

/// One part of a message's content.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ContentPart {
    /// Plain text.
    Text(String),
    /// An image as a URL; for the vision describer a `data:image/png;base64,…` URL (see
    /// [`ContentPart::png`]), so nothing but the request itself leaves the page.
    ImageUrl(String),
}

impl ContentPart {
    /// An image part from PNG bytes, as a data URL.
    pub fn png(png: &[u8]) -> Self {
        let encoded = base64::engine::general_purpose::STANDARD.encode(png);
        ContentPart::ImageUrl(format!("data:image/png;base64,{encoded}"))
    }

    fn to_json(&self) -> Value {
        match self {
            ContentPart::Text(text) => json!({"type": "text", "text": text}),
            ContentPart::ImageUrl(url) => json!({"type": "image_url", "image_url": {"url": url}}),
        }
    }
}

/// One message of the conversation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Message {
    /// Who says it.
    pub role: Role,
    /// What is said, in order.
    pub content: Vec<ContentPart>,
}

impl Message {
    /// A message of plain text.
    pub fn text(role: Role, text: impl Into<String>) -> Self {
        Message {
            role,
            content: vec![ContentPart::Text(text.into())],
        }
    }

    /// A system message.
    pub fn system(text: impl Into<String>) -> Self {
        Message::text(Role::System, text)
    }

    /// A user message.
    pub fn user(text: impl Into<String>) -> Self {
        Message::text(Role::User, text)
    }

    /// An assistant message.
    pub fn assistant(text: impl Into<String>) -> Self {
        Message::text(Role::Assistant, text)
    }

    /// A user message of text followed by PNG images (for a vision model).
    pub fn user_with_pngs<'a>(
        text: impl Into<String>,
        pngs: impl IntoIterator<Item = &'a [u8]>,
    ) -> Self {
        let mut content = vec![ContentPart::Text(text.into())];
        content.extend(pngs.into_iter().map(ContentPart::png));
        Message {
            role: Role::User,
            content,
        }
    }

    /// True when the message carries an image.
    pub fn has_images(&self) -> bool {
        self.content
            .iter()
            .any(|p| matches!(p, ContentPart::ImageUrl(_)))
    }

    /// The message in the API's shape. Text-only content is sent as a plain string, the form
    /// every server accepts (several local ones reject the array form for text).
    pub fn to_json(&self) -> Value {
        let content = match self.content.as_slice() {
            [ContentPart::Text(text)] => Value::String(text.clone()),
            parts => Value::Array(parts.iter().map(ContentPart::to_json).collect()),
        };
        json!({"role": self.role.as_str(), "content": content})
    }
}

/// The shape the reply should have. With [`ReplyFormat::JsonObject`] the OpenAI API requires
/// the word "JSON" somewhere in the messages; saying so is the caller's job.
#[derive(Clone, Debug, PartialEq)]
pub enum ReplyFormat {
    /// JSON matching a JSON Schema, enforced by the server where it supports structured output.
    JsonSchema {
        /// The schema's name (letters, digits, `_` and `-`).
        name: String,
        /// The JSON Schema.
        schema: Value,
    },
    /// Any JSON object.
    JsonObject,
    /// Free text (no `response_format` is sent).
    Text,
}

impl ReplyFormat {
    /// How strictly this format constrains the reply (see [`FormatLevel`]).
    pub fn level(&self) -> FormatLevel {
        match self {
            ReplyFormat::JsonSchema { .. } => FormatLevel::JsonSchema,
            ReplyFormat::JsonObject => FormatLevel::JsonObject,
            ReplyFormat::Text => FormatLevel::Text,
        }
    }

    /// The `response_format` member for a request sent at `level` (the lower of this format's
    /// level and what the server is known to support), or `None` for no member.
    pub(crate) fn response_format(&self, level: FormatLevel) -> Option<Value> {
        match (self, level.min(self.level())) {
            (ReplyFormat::JsonSchema { name, schema }, FormatLevel::JsonSchema) => Some(json!({
                "type": "json_schema",
                "json_schema": {"name": name, "schema": schema, "strict": true},
            })),
            // Servers that take no json_schema (llama-cpp-python) read a schema beside
            // json_object and constrain the reply to it; others ignore the extra member.
            (ReplyFormat::JsonSchema { schema, .. }, FormatLevel::JsonObject) => {
                Some(json!({"type": "json_object", "schema": schema}))
            }
            (_, FormatLevel::JsonObject) => Some(json!({"type": "json_object"})),
            _ => None,
        }
    }
}

/// How strongly a request asks the server to constrain the reply; ordered from weakest to
/// strongest so that "what we send" is `min(requested, supported)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum FormatLevel {
    /// No `response_format`.
    Text,
    /// `{"type": "json_object"}`.
    JsonObject,
    /// `{"type": "json_schema", …}`.
    JsonSchema,
}

impl FormatLevel {
    /// The next weaker level, if any.
    pub fn weaker(self) -> Option<FormatLevel> {
        match self {
            FormatLevel::JsonSchema => Some(FormatLevel::JsonObject),
            FormatLevel::JsonObject => Some(FormatLevel::Text),
            FormatLevel::Text => None,
        }
    }
}

/// Sampling options for one request; `None` leaves the server's default.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChatOptions {
    /// Sampling temperature (0 for the most repeatable plans).
    pub temperature: Option<f32>,
    /// The most tokens the reply may have.
    pub max_tokens: Option<u32>,
    /// A seed, for servers that make sampling repeatable with one.
    pub seed: Option<u64>,
    /// Use [`super::LlmConfig::vision_model`] (falling back to the main model) for this request.
    pub vision: bool,
}

impl ChatOptions {
    /// Options for a vision request.
    pub fn vision() -> Self {
        ChatOptions {
            vision: true,
            ..ChatOptions::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_serialise_like_the_api() {
        assert_eq!(
            Message::system("be brief").to_json(),
            json!({"role": "system", "content": "be brief"})
        );
        let m = Message::user_with_pngs("what is shown?", [b"\x89PNG".as_slice()]);
        assert!(m.has_images());
        assert_eq!(
            m.to_json(),
            json!({"role": "user", "content": [
                {"type": "text", "text": "what is shown?"},
                {"type": "image_url", "image_url": {"url": "data:image/png;base64,iVBORw=="}},
            ]})
        );
    }

    #[test]
    fn formats_degrade_to_what_the_server_supports() {
        let schema = ReplyFormat::JsonSchema {
            name: "plan".into(),
            schema: json!({"type": "object"}),
        };
        assert_eq!(
            schema.response_format(FormatLevel::JsonSchema).unwrap()["json_schema"]["strict"],
            json!(true)
        );
        assert_eq!(
            schema.response_format(FormatLevel::JsonObject),
            Some(json!({"type": "json_object", "schema": {"type": "object"}}))
        );
        assert_eq!(schema.response_format(FormatLevel::Text), None);
        assert_eq!(
            ReplyFormat::JsonObject.response_format(FormatLevel::JsonSchema),
            Some(json!({"type": "json_object"}))
        );
        assert_eq!(
            ReplyFormat::Text.response_format(FormatLevel::JsonSchema),
            None
        );
    }
}
