//! `coma-serve [DIR] [--port N]`: the built page on localhost, without building the engine
//! (what `scripts/start.sh` runs; `coma serve` does the same from the full CLI).
//! `coma-serve --compress DIR` writes the brotli copies the build leaves beside the page's
//! files (`scripts/tools.sh`).
//! `coma-serve --bind WASM OUT_DIR` writes the page's JavaScript glue beside a copy of the wasm
//! (what `wasm-bindgen --target web` does; `scripts/tools.sh`).

fn main() {
    let mut args = std::env::args().skip(1);
    let mut dir = std::path::PathBuf::from("dist");
    let mut port = 8080u16;
    let mut compress = false;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--compress" => compress = true,
            "--bind" => {
                let (Some(wasm), Some(out)) = (args.next(), args.next()) else {
                    fail("--bind needs the built wasm and an output folder: --bind WASM OUT_DIR")
                };
                bind(wasm.as_ref(), out.as_ref());
                return;
            }
            "--port" => match args.next().and_then(|p| p.parse().ok()) {
                Some(p) => port = p,
                None => fail("--port needs a port number (1-65535)"),
            },
            "-h" | "--help" => {
                println!("usage: coma-serve [DIR (default dist)] [--port N (default 8080)]");
                println!("       coma-serve --compress DIR   (writes brotli copies of its files)");
                println!(
                    "       coma-serve --bind WASM OUT_DIR   (writes the page's JavaScript glue)"
                );
                return;
            }
            other if other.starts_with('-') => fail(&format!("unknown option {other}")),
            other => dir = other.into(),
        }
    }
    if compress {
        match coma_serve::compress_dir(&dir, coma_serve::COMPRESSED) {
            Ok((before, after)) => println!(
                "brotli copies in {}: {:.1} MB as {:.1} MB",
                dir.display(),
                before as f64 / 1e6,
                after as f64 / 1e6
            ),
            Err(e) => fail(&format!("{e:#}")),
        }
        return;
    }
    if let Err(e) = coma_serve::serve_page(&dir, port) {
        fail(&format!("{e:#}"));
    }
}

#[cfg(feature = "bind")]
fn bind(wasm: &std::path::Path, out: &std::path::Path) {
    match coma_serve::bind::bind_page(wasm, out) {
        Ok(()) => println!(
            "wrote the page's JavaScript glue and wasm into {}",
            out.display()
        ),
        Err(e) => fail(&format!("{e:#}")),
    }
}

#[cfg(not(feature = "bind"))]
fn bind(_: &std::path::Path, _: &std::path::Path) {
    fail("this coma-serve was built without its `bind` feature")
}

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1);
}
