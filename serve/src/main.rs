//! `coma-serve [DIR] [--port N]`: the built page on localhost, without building the engine
//! (what `scripts/start.sh` runs; `coma serve` does the same from the full CLI).

fn main() {
    let mut args = std::env::args().skip(1);
    let mut dir = std::path::PathBuf::from("dist");
    let mut port = 8080u16;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--port" => match args.next().and_then(|p| p.parse().ok()) {
                Some(p) => port = p,
                None => fail("--port needs a port number (1-65535)"),
            },
            "-h" | "--help" => {
                println!("usage: coma-serve [DIR (default dist)] [--port N (default 8080)]");
                return;
            }
            other if other.starts_with('-') => fail(&format!("unknown option {other}")),
            other => dir = other.into(),
        }
    }
    if let Err(e) = coma_serve::serve_page(&dir, port) {
        fail(&format!("{e:#}"));
    }
}

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1);
}
