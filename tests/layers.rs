//! The workspace's layers hold: `vehsim-core` (physics and engine) reads and writes no files and
//! depends on no file format or chart crate (serde only behind its `serde` feature);
//! `vehsim-spec` depends on the core only, not on the application; the FMU on core and spec only,
//! the Python extension on the application for discovery alone; and no crate has a cycle
//! among its top-level modules. docs/design.md §1 shows the module graph these tests check.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The packages `cargo tree` lists as normal (non-dev, non-build) dependencies of `package`.
fn dependencies(package: &str, features: &[&str]) -> BTreeSet<String> {
    let mut cmd = Command::new(env!("CARGO"));
    cmd.current_dir(root())
        .args(["tree", "--locked", "--offline", "-p", package, "-e", "normal", "--prefix", "none"])
        .args(["--format", "{p}"]);
    cmd.args(features);
    let out = cmd.output().expect("cargo tree runs");
    assert!(out.status.success(), "cargo tree -p {package}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

const FILE_FORMATS_AND_FRONT_ENDS: [&str; 9] =
    ["toml", "csv", "plotters", "png", "clap", "serde_path_to_error", "indicatif", "signal-hook", "vehsim-spec"];

#[test]
fn core_depends_on_no_file_format_and_on_serde_only_by_feature() {
    // The whole tree: no file format, no front end, no JSON (serde itself comes in through
    // ode_solvers, which depends on it unconditionally).
    let plain = dependencies("vehsim-core", &["--no-default-features"]);
    for banned in FILE_FORMATS_AND_FRONT_ENDS.iter().chain(&["serde_json", "vehsim"]) {
        assert!(!plain.contains(*banned), "vehsim-core depends on {banned}: {plain:?}");
    }
    // Its own dependencies: serde and serde_json only with the feature.
    let direct = dependencies("vehsim-core", &["--no-default-features", "--depth", "1"]);
    assert!(direct.contains("nalgebra") && !direct.contains("serde") && !direct.contains("serde_json"), "{direct:?}");
    let with_serde = dependencies("vehsim-core", &["--features", "serde", "--depth", "1"]);
    assert!(with_serde.contains("serde") && with_serde.contains("serde_json"), "{with_serde:?}");
    let all_with_serde = dependencies("vehsim-core", &["--features", "serde"]);
    for banned in FILE_FORMATS_AND_FRONT_ENDS.iter().chain(&["vehsim"]) {
        assert!(!all_with_serde.contains(*banned), "vehsim-core (serde) depends on {banned}");
    }
}

#[test]
fn spec_depends_on_the_core_and_not_on_the_application() {
    let deps = dependencies("vehsim-spec", &[]);
    assert!(deps.contains("vehsim-core") && deps.contains("toml"), "{deps:?}");
    for banned in ["vehsim", "plotters", "clap", "indicatif", "signal-hook"] {
        assert!(!deps.contains(banned), "vehsim-spec depends on {banned}");
    }
}

#[test]
fn the_fmu_depends_on_core_and_spec_only() {
    let deps = dependencies("vehsim-fmu", &[]);
    assert!(deps.contains("vehsim-core") && deps.contains("vehsim-spec"), "{deps:?}");
    for banned in ["vehsim", "plotters", "clap", "indicatif", "signal-hook"] {
        assert!(!deps.contains(banned), "vehsim-fmu depends on {banned}");
    }
}

/// The Python extension reaches the application crate for discovery only (`vehsim.discover`
/// writes reports and plots); sweeps, runs, steps and the contact patch come from core and spec.
#[test]
fn python_uses_the_application_for_discovery_only() {
    let src = code(&root().join("python/src/lib.rs"));
    let uses: BTreeSet<&str> = src
        .match_indices("vehsim::")
        .map(|(i, _)| {
            src[i + "vehsim::".len()..].split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap_or("")
        })
        .collect();
    assert_eq!(uses, BTreeSet::from(["discover"]), "python/src/lib.rs uses the application's {uses:?}");
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(sources(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// The text of a source file without its comments (line comments and doc comments).
fn code(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn core_reads_and_writes_no_files() {
    let dir = root().join("crates/vehsim-core/src");
    let files = sources(&dir);
    assert!(files.len() > 30, "{} core sources", files.len());
    for f in files {
        let text = code(&f);
        for banned in
            ["std::fs", " fs::", "(fs::", "File::", "OpenOptions", "read_dir", "std::env::var", "include_str!(\"/"]
        {
            assert!(!text.contains(banned), "{} uses {banned}", f.display());
        }
    }
}

/// Top-level module -> the top-level modules of the same crate it names (`crate::x`), for the
/// crate whose sources are in `dir`.
fn module_graph(dir: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut g = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if name == "lib" || name == "main" {
            continue;
        }
        let files = if p.is_dir() { sources(&p) } else { vec![p.clone()] };
        let mut deps = BTreeSet::new();
        for f in files {
            let text = code(&f);
            // `crate::x` anywhere, and `use crate::{x::.., y::..}` groups
            for (i, _) in text.match_indices("crate::") {
                let rest = &text[i + 7..];
                if let Some(group) = rest.strip_prefix('{') {
                    let body = &group[..group.find(';').unwrap_or(group.len())];
                    for part in body.split(',') {
                        let m: String = part
                            .trim()
                            .trim_start_matches('{')
                            .chars()
                            .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                            .collect();
                        if !m.is_empty() && part.trim().trim_start_matches('{')[m.len()..].starts_with("::") {
                            deps.insert(m);
                        }
                    }
                } else {
                    let m: String = rest.chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect();
                    if !m.is_empty() {
                        deps.insert(m);
                    }
                }
            }
        }
        deps.remove(&name);
        g.insert(name, deps);
    }
    g
}

/// A cycle in `g` as a list of modules, if there is one (depth-first search).
fn find_cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in g.get(n).into_iter().flatten().filter(|m| g.contains_key(*m)) {
            match state.get(m.as_str()) {
                Some(1) => {
                    let at = stack.iter().position(|s| s == m).unwrap();
                    return Some(stack[at..].iter().cloned().chain([m.clone()]).collect());
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(m, g, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in g.keys() {
        if !state.contains_key(n) {
            if let Some(c) = visit(n, g, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn no_crate_has_a_module_cycle() {
    for dir in ["crates/vehsim-core/src", "crates/vehsim-spec/src", "src"] {
        let g = module_graph(&root().join(dir));
        assert!(g.len() >= 8, "{dir}: {g:?}");
        assert_eq!(find_cycle(&g), None, "{dir}: module cycle; graph {g:?}");
    }
}

#[test]
fn the_cycle_finder_finds_a_cycle() {
    let g: BTreeMap<String, BTreeSet<String>> = [("a", &["b"][..]), ("b", &["c"]), ("c", &["a"]), ("d", &[])]
        .iter()
        .map(|(k, v)| (k.to_string(), v.iter().map(|s| s.to_string()).collect()))
        .collect();
    assert_eq!(find_cycle(&g), Some(vec!["a".into(), "b".into(), "c".into(), "a".into()]));
}

/// `python3 scripts/api_listing.py ARGS` from the project root; its exit status and output.
fn api_listing(args: &[&str]) -> (bool, String) {
    let out = Command::new("python3")
        .current_dir(root())
        .arg("scripts/api_listing.py")
        .args(args)
        .output()
        .expect("python3 runs (README's set-up needs it)");
    (out.status.success(), format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr)))
}

#[test]
fn the_public_api_listing_is_current() {
    let (ok, msg) = api_listing(&["--check"]);
    assert!(ok, "{msg}");
    let text = std::fs::read_to_string(root().join("docs/api.md")).unwrap();
    for item in ["fn `simulate`", "struct `Simulation`", "struct `StepRun`", "trait `TyreModel`", "struct `RunConfig`"]
    {
        assert!(text.contains(item), "docs/api.md lacks {item}");
    }
}

#[test]
fn no_public_item_of_core_or_spec_is_dead() {
    let (ok, msg) = api_listing(&["--unused"]);
    assert!(ok, "public items named nowhere else:\n{msg}");
}
