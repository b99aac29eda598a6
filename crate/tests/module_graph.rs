//! The library's top-level modules depend on each other one way: no module reaches, through
//! the `crate::` paths of its non-test code, a module that reaches it back. A cycle makes the
//! layers meaningless (each side can only be understood with the other), so this test names
//! the first one it finds, with the file of each hop. And the layers are the ones `lib.rs`
//! and the README draw ([`LAYERS`]): a module imports only from its own layer or those below;
//! an import that goes up a layer fails, naming the file.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The top-level modules in layers, from the top down, as `lib.rs` and the README draw them:
/// the lab that assembles and measures above the engine, the engine above the agents, and so
/// on down to the pure pieces (geometry, features, the metrics) at the bottom.
const LAYERS: &[&[&str]] = &[
    &["export"],
    &["eval", "train", "bench"],
    &["session"],
    &["agents"],
    &["share", "plan"],
    &["model", "text", "trajectory"],
    &["feet", "posture"],
    &[
        "gltf",
        "motion_file",
        "dataset",
        "mocap",
        "bvh",
        "posecodes",
        "render",
        "figure",
        "features",
        "metrics",
        "skeleton",
        "limb",
        "timing",
        "geom",
        "rng",
        "npy",
        "quant",
        "weights",
        "executor",
    ],
];

/// The layer of a top-level module (0 is the top); `None` for a module no layer names.
fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// Top-level module → (module it names → a file that names it).
type Graph = BTreeMap<String, BTreeMap<String, PathBuf>>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without its comments and its test module (by the convention of this
/// tree, `#[cfg(test)] mod tests` closes a file, or lives in a `tests.rs` of its own).
fn non_test_code(text: &str) -> String {
    let end = [
        "#[cfg(test)]\nmod tests",
        "#[cfg(test)]\npub(crate) mod tests",
    ]
    .iter()
    .filter_map(|m| text.find(m))
    .min()
    .unwrap_or(text.len());
    text[..end]
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

fn graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut graph = Graph::new();
    for file in files {
        let relative = file.strip_prefix(src).unwrap();
        let top = relative
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        if top == "bin" || top == "lib" || file.file_name().unwrap() == "tests.rs" {
            continue;
        }
        let code = non_test_code(&std::fs::read_to_string(&file).unwrap());
        let edges = graph.entry(top.clone()).or_default();
        for (at, _) in code.match_indices("crate::") {
            let name: String = code[at + 7..]
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_' || c.is_ascii_digit())
                .collect();
            if !name.is_empty() && name != top {
                edges.entry(name).or_insert_with(|| relative.to_path_buf());
            }
        }
    }
    graph
}

/// A cycle through the graph, as its modules in order, if there is one.
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &Graph,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|n| n == node) {
            let mut cycle = path[at..].to_vec();
            cycle.push(node.to_string());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flat_map(|e| e.keys()) {
            if let Some(cycle) = visit(next, graph, path, done) {
                return Some(cycle);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| visit(n, graph, &mut Vec::new(), &mut done))
}

#[test]
fn top_level_modules_depend_on_each_other_one_way() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = graph(&src);
    assert!(graph.len() > 10, "read {} modules", graph.len());
    // The engine sits above the agents and the model; nothing below imports it.
    assert!(graph["session"].contains_key("agents"));
    if let Some(cycle) = find_cycle(&graph) {
        let hops: Vec<String> = cycle
            .windows(2)
            .map(|w| format!("{} → {} ({})", w[0], w[1], graph[&w[0]][&w[1]].display()))
            .collect();
        panic!(
            "the modules import each other in a cycle: {}",
            hops.join(", ")
        );
    }
}

#[test]
fn every_import_goes_down_the_layers_or_stays_in_its_own() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = graph(&src);
    let mut wrong = Vec::new();
    for (module, edges) in &graph {
        let Some(own) = layer_of(module) else {
            wrong.push(format!("{module} is in no layer of LAYERS"));
            continue;
        };
        for (named, file) in edges {
            match layer_of(named) {
                Some(l) if l < own => wrong.push(format!(
                    "{module} imports {named}, a layer above it ({})",
                    file.display()
                )),
                None if graph.contains_key(named) => {
                    wrong.push(format!("{named} is in no layer of LAYERS"))
                }
                _ => {}
            }
        }
    }
    wrong.sort();
    wrong.dedup();
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // The test sees an import that goes up: the lab's protocol runs the engine.
    assert!(layer_of("eval") < layer_of("session") && graph["eval"].contains_key("session"));
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let edge = |a: &str, b: &str| {
        (
            a.to_string(),
            BTreeMap::from([(b.to_string(), PathBuf::new())]),
        )
    };
    let cyclic: Graph = [edge("a", "b"), edge("b", "c"), edge("c", "a")].into();
    assert_eq!(find_cycle(&cyclic).unwrap().len(), 4);
    let chain: Graph = [edge("a", "b"), edge("b", "c")].into();
    assert_eq!(find_cycle(&chain), None);
    assert_eq!(
        non_test_code("use crate::a; // crate::b\n#[cfg(test)]\nmod tests { use crate::c; }"),
        "use crate::a; "
    );
}
