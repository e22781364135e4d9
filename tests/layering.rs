//! The layering of docs/architecture.md ("Layers"), kept by a test: every `crate::` path in
//! the library's non-test code names a module of a lower layer than its own, so the top-level
//! modules form no cycle. Unit tests (from a file's `#[cfg(test)]` on) may use any module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The layers, bottom first, as docs/architecture.md lists them.
fn layers() -> BTreeMap<String, usize> {
    let text = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let start = text
        .find("<!-- layers:")
        .expect("docs/architecture.md has a layers block");
    let block = &text[start..];
    let open = block.find("```text\n").expect("the layers block is fenced") + 8;
    let close = open + block[open..].find("```").unwrap();
    let mut out = BTreeMap::new();
    for line in block[open..close].lines() {
        let mut words = line.split_whitespace();
        let Some(level) = words.next() else { continue };
        let level: usize = level.parse().expect("a layer line starts with its number");
        words.next(); // the layer's name
        for module in words {
            assert!(
                out.insert(module.to_string(), level).is_none(),
                "{module} is in two layers"
            );
        }
    }
    out
}

/// The library's top-level modules (those `src/lib.rs` declares; the binary's own modules,
/// `src/cli`, are not the library's) and, for each, its files.
fn modules() -> BTreeMap<String, Vec<PathBuf>> {
    let src = root().join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let mut out = BTreeMap::new();
    for line in lib.lines() {
        let decl = line.trim().trim_start_matches("pub ");
        let Some(name) = decl.strip_prefix("mod ").and_then(|r| r.strip_suffix(';')) else {
            continue;
        };
        let (dir, file) = (src.join(name), src.join(format!("{name}.rs")));
        let mut files = Vec::new();
        if dir.is_dir() {
            collect(&dir, &mut files);
        }
        if file.is_file() {
            files.push(file);
        }
        assert!(
            !files.is_empty(),
            "src/lib.rs declares {name}, which has no file"
        );
        out.insert(name.to_string(), files);
    }
    out
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            collect(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level modules that `file` names as `crate::module`, outside comments and unit tests,
/// with the line of the first use of each.
fn uses(file: &Path) -> BTreeMap<String, usize> {
    let text = std::fs::read_to_string(file).unwrap();
    let mut out = BTreeMap::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            break;
        }
        if code.starts_with("//") {
            continue;
        }
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            // `$crate::` in a macro is the crate root too; anything else ending in `crate` is not.
            let before = &rest[..i];
            let ident_before = before
                .chars()
                .last()
                .is_some_and(|c| c.is_alphanumeric() || c == '_');
            rest = &rest[i + 7..];
            if ident_before {
                continue;
            }
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.entry(name).or_insert(n + 1);
        }
    }
    out
}

#[test]
fn every_module_uses_only_the_layers_below_it() {
    let layers = layers();
    let modules = modules();
    let listed: BTreeSet<&String> = layers.keys().collect();
    let present: BTreeSet<&String> = modules.keys().collect();
    let unlisted: Vec<_> = present.difference(&listed).collect();
    assert!(
        unlisted.is_empty(),
        "modules in no layer of docs/architecture.md: {unlisted:?}"
    );
    let missing: Vec<_> = listed.difference(&present).collect();
    assert!(
        missing.is_empty(),
        "layers name modules that do not exist: {missing:?}"
    );
    let mut wrong = Vec::new();
    let mut edges = 0;
    for (module, files) in &modules {
        let own = layers[module];
        for file in files {
            for (used, line) in uses(file) {
                if used == *module || !layers.contains_key(&used) {
                    continue; // itself, or not a module (a macro, `crate::` alone)
                }
                edges += 1;
                if layers[&used] >= own {
                    wrong.push(format!(
                        "{}:{line}: {module} (layer {own}) uses {used} (layer {})",
                        file.strip_prefix(root()).unwrap().display(),
                        layers[&used]
                    ));
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "uses against the layering:\n{}",
        wrong.join("\n")
    );
    // Not vacuous: the modules do use one another.
    assert!(edges > 50, "{edges} uses between modules found");
}

/// The reader of `crate::` paths sees what it must: a use of a higher layer in a file is caught.
#[test]
fn the_reader_finds_uses_and_skips_comments_and_unit_tests() {
    let dir = std::env::temp_dir().join(format!("penumbra-layering-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("probe.rs");
    std::fs::write(
        &file,
        "use crate::math::Frame;\n// crate::app is only named here\nfn f() { let _ = crate::render::Image::new(1, 1); }\nmacro_rules! m { () => { $crate::scene::Scene } }\n#[cfg(test)]\nmod tests { use crate::app; }\n",
    )
    .unwrap();
    let found: Vec<(String, usize)> = uses(&file).into_iter().collect();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        found,
        vec![
            ("math".to_string(), 1),
            ("render".to_string(), 3),
            ("scene".to_string(), 4)
        ]
    );
}

/// Where the library reads its process's environment, outside comments and unit tests: the
/// lines of `file` that call `env::var` or `env::var_os`.
fn environment_reads(file: &Path) -> Vec<usize> {
    let text = std::fs::read_to_string(file).unwrap();
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            break;
        }
        if !code.starts_with("//") && (code.contains("env::var(") || code.contains("env::var_os("))
        {
            out.push(n + 1);
        }
    }
    out
}

/// The library reads no configuration from the environment: its callers do (the command line,
/// `src/cli`, and Python, outside `src/`) and pass it in; only the workbench's launch reads the
/// one variable that picks the window's painter before any scene exists.
#[test]
fn only_the_callers_read_the_environment() {
    let launch = root().join("src/app/launch.rs");
    let mut reads = Vec::new();
    for files in modules().values() {
        for file in files {
            let lines = environment_reads(file);
            if *file == launch {
                assert_eq!(lines.len(), 1, "the launch reads PENUMBRA_RENDERER only");
                continue;
            }
            for line in lines {
                reads.push(format!(
                    "{}:{line}",
                    file.strip_prefix(root()).unwrap().display()
                ));
            }
        }
    }
    assert!(
        reads.is_empty(),
        "the library reads the environment at:\n{}",
        reads.join("\n")
    );
    // Not vacuous: the reader sees the command line's reads.
    assert!(!environment_reads(&root().join("src/cli/process_env.rs")).is_empty());
}
