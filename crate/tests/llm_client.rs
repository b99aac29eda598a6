//! The LLM client against a scripted server on 127.0.0.1: formats, retries, downgrades,
//! errors, and that the API key goes only where it should.

use coma::agents::llm::script_server::{ScriptServer, ScriptedReply};
use coma::agents::llm::{
    parse_json_content, Backoff, ChatOptions, ChatReply, FormatLevel, LlmClient, LlmConfig,
    LlmError, Message, ReplyFormat, UreqTransport,
};
use serde::Deserialize;
use serde_json::{json, Value};
use std::path::Path;
use std::time::{Duration, Instant};

const KEY: &str = "sk-test-5ecret-key-0123456789";

/// Short waits so the retry tests take milliseconds.
fn config(base_url: String) -> LlmConfig {
    LlmConfig {
        timeout: Duration::from_secs(5),
        max_retries: 2,
        backoff: Backoff {
            initial: Duration::from_millis(100),
            max: Duration::from_millis(400),
            retry_after_cap: Duration::from_millis(300),
        },
        ..LlmConfig::new(base_url, "test-model")
    }
    .with_api_key(KEY)
}

fn client(server: &ScriptServer) -> LlmClient<UreqTransport> {
    LlmClient::native(config(server.base_url())).unwrap()
}

fn schema_format() -> ReplyFormat {
    ReplyFormat::JsonSchema {
        name: "plan".into(),
        schema: json!({
            "type": "object",
            "properties": {"segments": {"type": "array"}},
            "required": ["segments"],
            "additionalProperties": false,
        }),
    }
}

fn ask(client: &LlmClient<UreqTransport>, format: &ReplyFormat) -> Result<ChatReply, LlmError> {
    let messages = [
        Message::system("You plan motions. Reply in JSON."),
        Message::user("A person walks forward, then bows."),
    ];
    client.chat_blocking(&messages, format, &ChatOptions::default())
}

/// Asserts the key is nowhere in the error's Display or Debug, and returns the Display.
fn shown(error: &LlmError) -> String {
    let display = error.to_string();
    let debug = format!("{error:?}");
    assert!(!display.contains(KEY) && !debug.contains(KEY), "{debug}");
    display
}

#[derive(Debug, Deserialize, PartialEq)]
struct Plan {
    segments: Vec<Segment>,
}

#[derive(Debug, Deserialize, PartialEq)]
struct Segment {
    text: String,
    seconds: f32,
}

#[test]
fn json_schema_request_and_reply() {
    let server = ScriptServer::start([ScriptedReply::completion(r#"{"segments": []}"#)]).unwrap();
    let client = client(&server);
    let options = ChatOptions {
        temperature: Some(0.0),
        max_tokens: Some(512),
        seed: Some(42),
        vision: false,
    };
    let reply = client
        .chat_blocking(&[Message::user("plan")], &schema_format(), &options)
        .unwrap();
    assert_eq!(reply.content, r#"{"segments": []}"#);
    assert_eq!(reply.format, FormatLevel::JsonSchema);
    assert_eq!(reply.attempts, 1);
    assert_eq!(reply.finish_reason.as_deref(), Some("stop"));
    assert_eq!(reply.model.as_deref(), Some("script"));
    assert_eq!(reply.usage.map(|u| u.completion_tokens), Some(5));

    let requests = server.requests();
    assert_eq!(requests.len(), 1);
    let request = &requests[0];
    assert_eq!(request.method, "POST");
    assert_eq!(request.path, "/v1/chat/completions");
    assert_eq!(
        request.header("authorization"),
        Some(format!("Bearer {KEY}").as_str())
    );
    assert_eq!(request.header("content-type"), Some("application/json"));
    let body = request.json();
    assert_eq!(body["model"], "test-model");
    assert_eq!(
        body["messages"],
        json!([{"role": "user", "content": "plan"}])
    );
    assert_eq!(body["response_format"]["type"], "json_schema");
    assert_eq!(body["response_format"]["json_schema"]["name"], "plan");
    assert_eq!(body["response_format"]["json_schema"]["strict"], true);
    assert_eq!(
        body["response_format"]["json_schema"]["schema"]["required"],
        json!(["segments"])
    );
    assert_eq!(body["temperature"], 0.0);
    assert_eq!(body["max_tokens"], 512);
    assert_eq!(body["seed"], 42);
}

#[test]
fn no_key_no_authorization_header() {
    let server = ScriptServer::start([ScriptedReply::completion("hi")]).unwrap();
    let config = LlmConfig::new(server.base_url(), "m");
    let client = LlmClient::native(config).unwrap();
    ask(&client, &ReplyFormat::Text).unwrap();
    let request = &server.requests()[0];
    assert_eq!(request.header("authorization"), None);
    assert!(request.json().get("response_format").is_none());
}

#[test]
fn rate_limit_is_retried_after_a_backoff() {
    let server = ScriptServer::start([
        ScriptedReply::error(429, "rate limit reached"),
        ScriptedReply::completion(r#"{"segments": []}"#),
    ])
    .unwrap();
    let start = Instant::now();
    let reply = ask(&client(&server), &schema_format()).unwrap();
    assert!(
        start.elapsed() >= Duration::from_millis(100),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(reply.attempts, 2);
    assert_eq!(server.requests().len(), 2);
}

#[test]
fn retry_after_is_honoured_up_to_the_cap() {
    let server = ScriptServer::start([
        ScriptedReply::error(429, "slow down").with_header("Retry-After", "30"),
        ScriptedReply::completion("{}"),
    ])
    .unwrap();
    let start = Instant::now();
    ask(&client(&server), &ReplyFormat::JsonObject).unwrap();
    let elapsed = start.elapsed();
    // 300 ms (the cap), not 30 s and not the 100 ms backoff.
    assert!(elapsed >= Duration::from_millis(300), "{elapsed:?}");
    assert!(elapsed < Duration::from_secs(10), "{elapsed:?}");
}

#[test]
fn server_errors_give_up_after_max_retries() {
    let server = ScriptServer::start([
        ScriptedReply::error(503, "loading model"),
        ScriptedReply::error(503, "loading model"),
        ScriptedReply::error(503, "loading model"),
        ScriptedReply::completion("never reached"),
    ])
    .unwrap();
    let start = Instant::now();
    let error = ask(&client(&server), &schema_format()).unwrap_err();
    // Backoff 100 ms, then 200 ms.
    assert!(
        start.elapsed() >= Duration::from_millis(300),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(
        error,
        LlmError::Server {
            status: 503,
            attempts: 3,
            detail: "loading model".into()
        }
    );
    let message = shown(&error);
    assert!(
        message.contains("server error (503) on all 3 attempts"),
        "{message}"
    );
    assert!(message.contains("loading model"), "{message}");
    assert_eq!(server.requests().len(), 3);
    assert_eq!(server.remaining(), 1);
}

#[test]
fn other_5xx_are_retried_and_rate_limits_reported() {
    let server = ScriptServer::start([
        ScriptedReply::new(500, "oops"),
        ScriptedReply::new(502, "<html>Bad Gateway</html>"),
        ScriptedReply::new(504, ""),
        ScriptedReply::completion("ok"),
    ])
    .unwrap();
    let mut config = config(server.base_url());
    config.max_retries = 3;
    let patient = LlmClient::native(config).unwrap();
    assert_eq!(ask(&patient, &ReplyFormat::Text).unwrap().attempts, 4);

    let server = ScriptServer::start((0..3).map(|_| ScriptedReply::error(429, "quota"))).unwrap();
    let error = ask(&client(&server), &ReplyFormat::Text).unwrap_err();
    assert!(
        matches!(error, LlmError::RateLimited { attempts: 3, .. }),
        "{error:?}"
    );
    assert!(shown(&error).contains("429"));
}

#[test]
fn client_errors_are_not_retried_and_say_what_to_do() {
    let cases: [(u16, &str); 4] = [
        (401, "the endpoint rejected the API key"),
        (403, "403 Forbidden"),
        (404, "check the base URL"),
        (400, "the endpoint refused the request (400)"),
    ];
    for (status, expected) in cases {
        let server = ScriptServer::start([
            ScriptedReply::error(status, "nope"),
            ScriptedReply::completion("never reached"),
        ])
        .unwrap();
        let error = ask(&client(&server), &ReplyFormat::Text).unwrap_err();
        let message = shown(&error);
        assert!(message.contains(expected), "{status}: {message}");
        assert_eq!(server.requests().len(), 1, "{status} was retried");
        if status == 404 {
            assert!(message.contains(&format!("{}/chat/completions", server.base_url())));
            assert!(message.contains("test-model"), "{message}");
        }
    }
}

#[test]
fn redirects_say_where_to_go() {
    let server = ScriptServer::start([ScriptedReply::new(301, "")
        .with_header("Location", "https://api.example.com/v1/chat/completions")])
    .unwrap();
    let error = ask(&client(&server), &ReplyFormat::Text).unwrap_err();
    let message = shown(&error);
    assert!(
        message.contains("HTTP 301 redirecting to https://api.example.com/v1/chat/completions"),
        "{message}"
    );
}

#[test]
fn timeouts_are_retried_then_reported() {
    let slow = || ScriptedReply::completion("late").with_delay(Duration::from_millis(1500));
    let mut config = config(String::new());
    config.timeout = Duration::from_millis(300);
    config.max_retries = 1;

    let server = ScriptServer::start([slow(), ScriptedReply::completion("on time")]).unwrap();
    config.base_url = server.base_url();
    let client = LlmClient::native(config.clone()).unwrap();
    let reply = ask(&client, &ReplyFormat::Text).unwrap();
    assert_eq!((reply.content.as_str(), reply.attempts), ("on time", 2));

    let server = ScriptServer::start([slow(), slow()]).unwrap();
    config.base_url = server.base_url();
    let client = LlmClient::native(config).unwrap();
    let start = Instant::now();
    let error = ask(&client, &ReplyFormat::Text).unwrap_err();
    assert!(
        start.elapsed() < Duration::from_millis(1400),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(
        error,
        LlmError::Timeout {
            timeout: Duration::from_millis(300),
            attempts: 2
        }
    );
    let message = shown(&error);
    assert!(
        message.contains("did not answer within 0.3 s on all 2 attempts"),
        "{message}"
    );
}

#[test]
fn a_server_without_structured_output_is_downgraded_once_and_remembered() {
    let server = ScriptServer::start([
        ScriptedReply::error(400, "response_format json_schema is not supported"),
        ScriptedReply::error(
            400,
            "Invalid value for 'response_format.type': 'json_object'",
        ),
        ScriptedReply::completion("{\"segments\": []}"),
        ScriptedReply::completion("{\"segments\": []}"),
    ])
    .unwrap();
    let client = client(&server);
    let reply = ask(&client, &schema_format()).unwrap();
    assert_eq!(reply.format, FormatLevel::Text);
    assert_eq!(reply.attempts, 3);
    assert_eq!(client.supported_format(), FormatLevel::Text);
    // The next request goes straight to the format that worked.
    let reply = ask(&client, &schema_format()).unwrap();
    assert_eq!((reply.format, reply.attempts), (FormatLevel::Text, 1));

    let formats: Vec<Value> = server
        .requests()
        .iter()
        .map(|r| r.json()["response_format"]["type"].clone())
        .collect();
    assert_eq!(
        formats,
        [
            json!("json_schema"),
            json!("json_object"),
            Value::Null,
            Value::Null
        ]
    );
}

#[test]
fn llama_cpp_pythons_500_about_the_format_is_a_downgrade_that_keeps_the_schema() {
    // What llama-cpp-python 0.3 answers to a json_schema response_format: a validation
    // error under status 500. Its json_object mode takes the schema as an extension.
    let server = ScriptServer::start([
        ScriptedReply::new(
            500,
            r#"{"detail": [{"loc": ["body", "response_format", "type"], "msg": "Input should be 'text' or 'json_object'"}]}"#,
        ),
        ScriptedReply::completion("{\"segments\": []}"),
    ])
    .unwrap();
    let client = client(&server);
    let reply = ask(&client, &schema_format()).unwrap();
    assert_eq!(reply.format, FormatLevel::JsonObject);
    let sent = server.requests()[1].json();
    assert_eq!(sent["response_format"]["type"], "json_object");
    assert!(sent["response_format"]["schema"].is_object(), "{sent}");
}

#[test]
fn downgrade_from_a_committed_fixture() {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/llm/no_json_schema.jsonl");
    let server = ScriptServer::from_fixture(fixture).unwrap();
    let client = client(&server);
    let reply = ask(&client, &schema_format()).unwrap();
    assert_eq!(reply.format, FormatLevel::JsonObject);
    assert_eq!(client.supported_format(), FormatLevel::JsonObject);
    let plan: Plan = parse_json_content(&reply.content).unwrap();
    assert_eq!(plan.segments[0].text, "a person walks forward");
    assert_eq!(plan.segments[0].seconds, 4.0);
}

#[test]
fn a_400_that_is_not_about_the_format_is_not_downgraded() {
    let server = ScriptServer::start([
        ScriptedReply::error(400, "messages: too many tokens"),
        ScriptedReply::completion("never reached"),
    ])
    .unwrap();
    let client = client(&server);
    let error = ask(&client, &schema_format()).unwrap_err();
    assert!(
        matches!(error, LlmError::BadRequest { status: 400, .. }),
        "{error:?}"
    );
    assert!(shown(&error).contains("too many tokens"));
    assert_eq!(client.supported_format(), FormatLevel::JsonSchema);
}

#[test]
fn replies_that_are_not_completions_are_bad_replies() {
    let cases = [
        (
            ScriptedReply::new(200, "<html>It works!</html>"),
            "it is not JSON",
        ),
        (
            ScriptedReply::new(200, r#"{"object": "chat.completion"}"#),
            "it has no choices",
        ),
        (
            ScriptedReply::new(200, r#"{"choices": []}"#),
            "it has no choices",
        ),
        (ScriptedReply::completion("  "), "its content is empty"),
        (
            ScriptedReply::new(200, r#"{"error": {"message": "model overloaded"}}"#),
            "model overloaded",
        ),
    ];
    for (reply, expected) in cases {
        let server = ScriptServer::start([reply]).unwrap();
        let error = ask(&client(&server), &ReplyFormat::JsonObject).unwrap_err();
        assert!(matches!(error, LlmError::BadReply { .. }), "{error:?}");
        let message = shown(&error);
        assert!(message.contains(expected), "{message}");
    }
    // The excerpt of a long junk body is capped.
    let server = ScriptServer::start([ScriptedReply::new(200, "x".repeat(10_000))]).unwrap();
    let error = ask(&client(&server), &ReplyFormat::Text).unwrap_err();
    assert!(shown(&error).len() < 400, "{error}");
}

#[test]
fn hostile_replies_fixture() {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/llm/hostile_replies.jsonl");
    let server = ScriptServer::from_fixture(fixture).unwrap();
    let client = client(&server);
    let mut outcomes = Vec::new();
    while server.remaining() > 0 {
        let outcome = match ask(&client, &ReplyFormat::JsonObject) {
            Ok(reply) => match parse_json_content::<Plan>(&reply.content) {
                Ok(plan) => format!("plan {}", plan.segments[0].text),
                Err(e) => format!("retry: {}", &e[..e.find(" (").unwrap_or(e.len())]),
            },
            Err(LlmError::BadReply { reason, .. }) => format!("bad reply: {reason}"),
            Err(other) => panic!("{other:?}"),
        };
        outcomes.push(outcome);
    }
    assert_eq!(
        outcomes,
        [
            "plan a person waves",
            "plan a person bows",
            "plan a person jumps",
            "retry: your reply is cut off",
            "retry: your reply is not valid JSON",
            "retry: your reply does not match the required JSON schema",
            "bad reply: the model refused",
            "bad reply: its content is empty",
            "bad reply: its content is empty",
            "bad reply: it has no choices",
            "bad reply: it is an error, not a completion",
            "bad reply: it is not JSON",
        ]
    );
}

#[test]
fn a_body_over_the_cap_is_refused() {
    let huge = format!(
        "{{\"choices\": [{{\"message\": {{\"content\": \"{}\"}}}}]}}",
        "a".repeat(2 << 20)
    );
    let server = ScriptServer::start([ScriptedReply::new(200, huge)]).unwrap();
    let error = ask(&client(&server), &ReplyFormat::Text).unwrap_err();
    assert_eq!(error, LlmError::TooLarge { limit: 1 << 20 });
    assert!(shown(&error).contains("longer than 1048576 bytes"));

    let server = ScriptServer::start([ScriptedReply::completion(&"b".repeat(5_000))]).unwrap();
    let mut config = config(server.base_url());
    config.max_reply_bytes = 1_000;
    let error = ask(&LlmClient::native(config).unwrap(), &ReplyFormat::Text).unwrap_err();
    assert_eq!(error, LlmError::TooLarge { limit: 1_000 });
}

#[test]
fn the_key_goes_only_into_the_authorization_header() {
    let echo = format!("Incorrect API key provided: {KEY}. Find your key in the dashboard.");
    let server = ScriptServer::start([
        ScriptedReply::error(401, &echo),
        ScriptedReply::error(403, &echo),
        ScriptedReply::new(200, format!("not json {KEY}")),
        ScriptedReply::error(429, &echo),
        ScriptedReply::error(429, &echo),
        ScriptedReply::error(429, &echo),
    ])
    .unwrap();
    let client = client(&server);
    assert!(!format!("{client:?}").contains(KEY));
    assert!(!format!("{:?}", client.config()).contains(KEY));
    for _ in 0..4 {
        let error = ask(&client, &ReplyFormat::Text).unwrap_err();
        shown(&error);
    }
    let requests = server.requests();
    assert_eq!(requests.len(), 6);
    for request in &requests {
        assert_eq!(
            request.header("authorization"),
            Some(format!("Bearer {KEY}").as_str())
        );
        assert!(!request.body.contains(KEY));
    }
}

#[test]
fn connection_refused_is_a_network_error_that_mentions_cors() {
    let port = {
        let listener = std::net::TcpListener::bind(("127.0.0.1", 0)).unwrap();
        listener.local_addr().unwrap().port()
    };
    let base = format!("http://127.0.0.1:{port}/v1");
    let mut config = config(base.clone());
    config.backoff.initial = Duration::from_secs(2);
    let client = LlmClient::native(config).unwrap();
    let start = Instant::now();
    let error = ask(&client, &ReplyFormat::Text).unwrap_err();
    assert!(matches!(error, LlmError::Network { .. }), "{error:?}");
    let message = shown(&error);
    assert!(
        message.starts_with(&format!("could not reach {base};")),
        "{message}"
    );
    assert!(message.contains("local server (Ollama, llama.cpp, LM Studio, vLLM)"));
    assert!(message.contains("enable CORS for this page's origin"));
    // Not retried: the 2 s backoff was not waited.
    assert!(
        start.elapsed() < Duration::from_millis(1500),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn vision_requests_use_the_vision_model_and_image_parts() {
    let server = ScriptServer::start([ScriptedReply::completion("a person waving")]).unwrap();
    let mut config = config(server.base_url());
    config.vision_model = Some("test-vision".into());
    let client = LlmClient::native(config).unwrap();
    let message = Message::user_with_pngs("Describe the motion.", [b"\x89PNG\r\n".as_slice()]);
    client
        .chat_blocking(&[message], &ReplyFormat::Text, &ChatOptions::vision())
        .unwrap();
    let body = server.requests()[0].json();
    assert_eq!(body["model"], "test-vision");
    let parts = body["messages"][0]["content"].as_array().unwrap();
    assert_eq!(
        parts[0],
        json!({"type": "text", "text": "Describe the motion."})
    );
    assert_eq!(parts[1]["type"], "image_url");
    assert!(parts[1]["image_url"]["url"]
        .as_str()
        .unwrap()
        .starts_with("data:image/png;base64,"));
}

#[test]
fn settings_that_cannot_work_are_refused_up_front() {
    let cases = [
        (LlmConfig::new("", "m"), "base URL"),
        (LlmConfig::new("ftp://host/v1", "m"), "http://"),
        (LlmConfig::new("http://localhost:1/v1", " "), "model name"),
        (
            LlmConfig::new("http://localhost:1/v1", "m").with_api_key("sk-abc\ndef"),
            "cannot be sent in a header",
        ),
    ];
    for (config, expected) in cases {
        let error = LlmClient::native(config).unwrap_err();
        assert!(matches!(error, LlmError::InvalidConfig(_)), "{error:?}");
        assert!(error.to_string().contains(expected), "{error}");
    }
}
