//! A small static file server for the built page on localhost: correct MIME types (browsers
//! refuse to stream-compile wasm served as anything but `application/wasm`), no directory
//! listing, and no path outside the served folder. Where the build left a compressed copy
//! beside a file (`coma_web_bg.wasm.br` from [`compress_dir`], `.gz` from `gzip`; both made
//! by `scripts/tools.sh`), a browser that accepts that encoding gets the copy with its
//! `Content-Encoding`, brotli first: the page's wasm goes over the wire at a tenth of its
//! size (a sixth with gzip). Any static host can do the same (nginx: `brotli_static on`,
//! `gzip_static on`).

#[cfg(feature = "bind")]
pub mod bind;

use anyhow::{Context, Result};
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};

/// MIME type for a file name.
pub fn mime_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "wasm" => "application/wasm",
        "css" => "text/css; charset=utf-8",
        "json" => "application/json",
        "png" => "image/png",
        "svg" => "image/svg+xml",
        "md" | "txt" => "text/plain; charset=utf-8",
        "wgsl" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

/// The file a request path maps to, or `None` when it would leave `root`.
pub fn resolve(root: &Path, request_path: &str) -> Option<PathBuf> {
    let path = request_path.split(['?', '#']).next().unwrap_or("/");
    let mut out = root.to_path_buf();
    for c in Path::new(path.trim_start_matches('/')).components() {
        match c {
            Component::Normal(p) => out.push(p),
            Component::CurDir => {}
            _ => return None,
        }
    }
    if out.is_dir() {
        out.push("index.html");
    }
    Some(out)
}

fn respond(stream: &mut TcpStream, root: &Path) -> std::io::Result<()> {
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request = String::new();
    reader.read_line(&mut request)?;
    // Of the headers only If-None-Match matters: it lets the browser keep the weights in its
    // cache and ask only whether they changed.
    let mut line = String::new();
    let mut if_none_match = None;
    let mut accepts = Vec::new();
    while reader.read_line(&mut line)? > 2 {
        if let Some((name, value)) = line.split_once(':') {
            if name.eq_ignore_ascii_case("if-none-match") {
                if_none_match = Some(value.trim().to_string());
            } else if name.eq_ignore_ascii_case("accept-encoding") {
                accepts = value
                    .split(',')
                    .map(|c| c.split(';').next().unwrap_or("").trim().to_string())
                    .collect();
            }
        }
        line.clear();
    }
    let mut words = request.split_whitespace();
    let method = words.next().unwrap_or("");
    let target = words.next().unwrap_or("/");
    let mut etag = None;
    let mut encoding = "";
    let (status, mime, body) = match (method, resolve(root, target)) {
        ("GET" | "HEAD", Some(path)) => match read_encoded(&path, &accepts) {
            Ok((bytes, copy)) => {
                if let Some(copy) = copy {
                    encoding = copy.header;
                }
                let tag = entity_tag(&bytes);
                let fresh = if_none_match.as_deref() == Some(tag.as_str());
                etag = Some(tag);
                if fresh {
                    ("304 Not Modified", mime_type(&path), Vec::new())
                } else {
                    ("200 OK", mime_type(&path), bytes)
                }
            }
            Err(_) => (
                "404 Not Found",
                "text/plain; charset=utf-8",
                b"not found\n".to_vec(),
            ),
        },
        ("GET" | "HEAD", None) => (
            "403 Forbidden",
            "text/plain; charset=utf-8",
            b"forbidden\n".to_vec(),
        ),
        _ => (
            "405 Method Not Allowed",
            "text/plain; charset=utf-8",
            b"method not allowed\n".to_vec(),
        ),
    };
    let etag = etag.map_or(String::new(), |t| format!("ETag: {t}\r\n"));
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {mime}\r\nContent-Length: {}\r\nCache-Control: no-cache\r\nVary: Accept-Encoding\r\n{encoding}{etag}Connection: close\r\n\r\n",
        body.len()
    )?;
    if method != "HEAD" {
        stream.write_all(&body)?;
    }
    stream.flush()
}

/// A compressed copy the build may leave beside a file.
#[derive(Clone, Copy)]
struct Copy {
    /// The `Accept-Encoding` token that asks for it.
    token: &'static str,
    suffix: &'static str,
    header: &'static str,
}

/// The copies in the order they are preferred: brotli is the smaller.
const COPIES: [Copy; 2] = [
    Copy {
        token: "br",
        suffix: ".br",
        header: "Content-Encoding: br\r\n",
    },
    Copy {
        token: "gzip",
        suffix: ".gz",
        header: "Content-Encoding: gzip\r\n",
    },
];

/// The bytes to send for `path`: the first copy whose encoding the browser accepts and that
/// the build left (with that copy), else the file itself.
fn read_encoded(path: &Path, accepts: &[String]) -> std::io::Result<(Vec<u8>, Option<Copy>)> {
    let copy = COPIES
        .into_iter()
        .filter(|c| accepts.iter().any(|a| a == c.token))
        .find_map(|c| fresh_copy(path, c.suffix).map(|p| (p, c)));
    match copy {
        Some((p, c)) => Ok((std::fs::read(p)?, Some(c))),
        None => Ok((std::fs::read(path)?, None)),
    }
}

/// The copy with `suffix` beside `path`, when there is one at least as new as the file (a
/// copy older than its file is stale and never served).
fn fresh_copy(path: &Path, suffix: &str) -> Option<PathBuf> {
    let mut name = path.file_name()?.to_os_string();
    name.push(suffix);
    let copy = path.with_file_name(name);
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    (modified(&copy)? >= modified(path)?).then_some(copy)
}

/// Endings of the page's files worth a compressed copy (images and the like are compressed
/// already).
pub const COMPRESSED: &[&str] = &[
    ".wasm", ".js", ".html", ".json", ".bpk", ".i8", ".txt", ".npy", ".bin",
];

/// Brotli quality of a file's copy: 10 for the wasm (about a tenth of its size; 11 saves a
/// little more for twice the time, 9 clearly less), 9 for the rest (the weights, already
/// quantized, shrink little either way). `coma-serve --compress` prints the sizes it reached.
fn brotli_quality(name: &str) -> i32 {
    if name.ends_with(".wasm") {
        10
    } else {
        9
    }
}

/// Writes a brotli copy (`name.br`) beside every file under `dir` whose name ends with one
/// of `extensions` and that has no fresh copy yet; returns the bytes before and after.
pub fn compress_dir(dir: &Path, extensions: &[&str]) -> Result<(u64, u64)> {
    let (mut before, mut after) = (0u64, 0u64);
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).with_context(|| folder.display().to_string())? {
            let path = entry?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                stack.push(path);
            } else if extensions.iter().any(|e| name.ends_with(e)) {
                let copy = path.with_file_name(format!("{name}.br"));
                if fresh_copy(&path, ".br").is_none() {
                    let bytes = std::fs::read(&path).with_context(|| name.to_string())?;
                    let mut out = Vec::new();
                    let params = brotli::enc::BrotliEncoderParams {
                        quality: brotli_quality(name),
                        lgwin: 24,
                        ..Default::default()
                    };
                    brotli::BrotliCompress(&mut bytes.as_slice(), &mut out, &params)
                        .with_context(|| name.to_string())?;
                    std::fs::write(&copy, &out).with_context(|| copy.display().to_string())?;
                }
                before += std::fs::metadata(&path)?.len();
                after += std::fs::metadata(&copy)?.len();
            }
        }
    }
    Ok((before, after))
}

/// A strong entity tag of a file's contents (FNV-1a of the bytes and their length).
fn entity_tag(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("\"{:x}-{h:016x}\"", bytes.len())
}

/// Serves the built page in `root` (it must hold `index.html`) until the process is stopped.
pub fn serve_page(root: &Path, port: u16) -> Result<()> {
    if !root.join("index.html").exists() {
        anyhow::bail!(
            "{} has no index.html: build the page first (see README.md)",
            root.display()
        );
    }
    serve(root, port)
}

/// Serves `root` on `127.0.0.1:port` until the process is stopped.
pub fn serve(root: &Path, port: u16) -> Result<()> {
    let listener = TcpListener::bind(("127.0.0.1", port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{port}"))?;
    println!(
        "serving {} on http://127.0.0.1:{port}/ (Ctrl+C stops)",
        root.display()
    );
    for stream in listener.incoming() {
        let Ok(mut stream) = stream else { continue };
        let root = root.to_path_buf();
        std::thread::spawn(move || {
            let _ = respond(&mut stream, &root);
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_stay_inside_the_root() {
        let root = Path::new("/srv/page");
        assert_eq!(
            resolve(root, "/pkg/app.wasm?v=1"),
            Some(PathBuf::from("/srv/page/pkg/app.wasm"))
        );
        assert_eq!(resolve(root, "/../etc/passwd"), None);
        assert_eq!(resolve(root, "/a/../../b"), None);
    }

    /// Serves `root` for `requests` requests on a free port; returns a function that sends a
    /// GET for a file with extra header lines and returns the whole answer.
    fn server(root: &Path, requests: usize) -> impl Fn(&str, &str) -> String {
        let listener = TcpListener::bind(("127.0.0.1", 0)).unwrap();
        let port = listener.local_addr().unwrap().port();
        let root = root.to_path_buf();
        std::thread::spawn(move || {
            for stream in listener.incoming().take(requests) {
                let _ = respond(&mut stream.unwrap(), &root);
            }
        });
        move |file: &str, extra: &str| {
            use std::io::Read;
            let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
            write!(s, "GET /{file} HTTP/1.1\r\nHost: x\r\n{extra}\r\n").unwrap();
            // Lossy: a compressed body is not text, and the tests read only its headers.
            let mut out = Vec::new();
            s.read_to_end(&mut out).unwrap();
            String::from_utf8_lossy(&out).into_owned()
        }
    }

    #[test]
    fn a_cached_file_is_not_sent_again() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("w.bpk"), b"weights").unwrap();
        let get = server(dir.path(), 2);
        let first = get("w.bpk", "");
        assert!(
            first.starts_with("HTTP/1.1 200") && first.ends_with("weights"),
            "{first}"
        );
        let tag = first
            .lines()
            .find_map(|l| l.strip_prefix("ETag: "))
            .unwrap()
            .to_string();
        let again = get("w.bpk", &format!("If-None-Match: {tag}\r\n"));
        assert!(again.starts_with("HTTP/1.1 304"), "{again}");
        assert!(again.ends_with("\r\n\r\n"), "no body: {again}");
    }

    #[test]
    fn a_browser_that_accepts_gzip_gets_the_gzip_copy() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.wasm"), b"plain bytes").unwrap();
        std::fs::write(dir.path().join("a.wasm.gz"), b"gz bytes").unwrap();
        std::fs::write(dir.path().join("b.js"), b"no copy").unwrap();
        let get = server(dir.path(), 3);
        let gz = get("a.wasm", "Accept-Encoding: deflate, gzip;q=0.9, br\r\n");
        assert!(gz.contains("Content-Encoding: gzip\r\n"), "{gz}");
        assert!(gz.contains("Content-Type: application/wasm\r\n"), "{gz}");
        assert!(gz.ends_with("gz bytes"), "{gz}");
        let plain = get("a.wasm", "");
        assert!(!plain.contains("Content-Encoding"), "{plain}");
        assert!(plain.ends_with("plain bytes"), "{plain}");
        let no_copy = get("b.js", "Accept-Encoding: gzip\r\n");
        assert!(no_copy.ends_with("no copy") && !no_copy.contains("Content-Encoding"));
    }

    #[test]
    fn brotli_is_preferred_and_its_copies_decompress_to_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let text = "a person walks forward ".repeat(200);
        std::fs::create_dir(dir.path().join("pkg")).unwrap();
        std::fs::write(dir.path().join("pkg/a.wasm"), &text).unwrap();
        std::fs::write(dir.path().join("pkg/a.wasm.gz"), b"gz bytes").unwrap();
        std::fs::write(dir.path().join("b.png"), b"not compressed").unwrap();
        let (before, after) = compress_dir(dir.path(), &[".wasm"]).unwrap();
        assert_eq!(before, text.len() as u64);
        assert!(after < before / 10, "{after} of {before}");
        assert!(!dir.path().join("b.png.br").exists());
        let copy = std::fs::read(dir.path().join("pkg/a.wasm.br")).unwrap();
        let mut back = Vec::new();
        brotli::BrotliDecompress(&mut copy.as_slice(), &mut back).unwrap();
        assert_eq!(back, text.as_bytes());

        let get = server(dir.path(), 2);
        let br = get("pkg/a.wasm", "Accept-Encoding: gzip, deflate, br, zstd\r\n");
        assert!(br.contains("Content-Encoding: br\r\n"), "{br}");
        let gz = get("pkg/a.wasm", "Accept-Encoding: gzip\r\n");
        assert!(gz.contains("Content-Encoding: gzip\r\n") && gz.ends_with("gz bytes"));
    }

    #[test]
    fn wasm_has_its_mime_type() {
        assert_eq!(
            mime_type(Path::new("x/coma_web_bg.wasm")),
            "application/wasm"
        );
        assert_eq!(
            mime_type(Path::new("index.html")),
            "text/html; charset=utf-8"
        );
    }
}
