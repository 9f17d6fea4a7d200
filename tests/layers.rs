//! The core's modules form layers: a module may use only modules of lower
//! layers, so there are no cycles and each layer can be read, tested and
//! changed without the ones above it (docs/architecture.md, "Layers").

use std::path::{Path, PathBuf};

/// Each top-level module of `src/` and its layer, lowest first.
const LAYERS: &[(&str, u32)] = &[
    ("error", 0),
    ("geom", 0),
    ("choice", 0),
    // Cache hints for the resample and the field map's redo.
    ("prefetch", 0),
    ("shutter", 1),
    ("strokes", 1),
    ("features", 1),
    ("bspline", 1),
    ("image", 1),
    ("warp", 2),
    ("track", 2),
    ("transition", 3),
    ("snake", 3),
    // Suggested correspondences: corners matched with the tracker.
    ("suggest", 3),
    ("make_warp", 4),
    ("morph", 4),
    // The ghost view compares the dissolve's warped sources.
    ("views", 5),
    ("scene", 5),
    // Helpers for tests and benches: nothing else may use them.
    ("testing", 6),
];

fn layer(module: &str) -> u32 {
    LAYERS
        .iter()
        .find(|(m, _)| *m == module)
        .map(|(_, l)| *l)
        .unwrap_or_else(|| panic!("module {module} has no layer: add it to LAYERS"))
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read src") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source of a file without its test code.
fn non_test_code(path: &Path) -> Option<String> {
    let name = path.file_stem()?.to_str()?;
    if name == "tests" || name.ends_with("_tests") {
        return None;
    }
    let text = std::fs::read_to_string(path).ok()?;
    Some(match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => text[..i].to_owned(),
        None => text,
    })
}

/// `(module, used module)` for every `crate::x` path in the module's code.
fn uses(src: &Path) -> Vec<(String, String, PathBuf)> {
    let mut files = Vec::new();
    sources(src, &mut files);
    let mut found = Vec::new();
    for file in files {
        let rel = file.strip_prefix(src).expect("under src");
        let module = rel
            .components()
            .next()
            .and_then(|c| c.as_os_str().to_str())
            .map(|m| m.trim_end_matches(".rs").to_owned())
            .expect("a module");
        if module == "lib" {
            continue;
        }
        let Some(code) = non_test_code(&file) else {
            continue;
        };
        for (i, _) in code.match_indices("crate::") {
            let used: String = code[i + 7..]
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                .collect();
            if !used.is_empty() && used != module {
                found.push((module.clone(), used, file.clone()));
            }
        }
    }
    found
}

#[test]
fn modules_use_only_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let found = uses(&src);
    assert!(found.len() > 50, "the scan found the core's imports");
    let upward: Vec<String> = found
        .iter()
        .filter(|(m, u, _)| layer(u) >= layer(m))
        .map(|(m, u, f)| {
            format!(
                "{m} (layer {}) uses {u} (layer {}) in {}",
                layer(m),
                layer(u),
                f.display()
            )
        })
        .collect();
    assert!(upward.is_empty(), "{}", upward.join("\n"));
}

/// The scan sees what it must: a known downward use is found.
#[test]
fn the_scan_sees_known_uses() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let found = uses(&src);
    assert!(found
        .iter()
        .any(|(m, u, _)| m == "make_warp" && u == "warp"));
    assert!(found
        .iter()
        .any(|(m, u, _)| m == "scene" && u == "make_warp"));
}

/// The layer table in docs/architecture.md names every module (but the
/// test helpers) at the layer this scan holds it to.
#[test]
fn the_documented_layers_are_the_checked_ones() {
    let doc = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/architecture.md");
    let text = std::fs::read_to_string(doc).expect("read docs/architecture.md");
    let mut documented = Vec::new();
    for row in text.lines().filter_map(|l| l.strip_prefix("| ")) {
        let mut cells = row.split(" | ");
        let (Some(n), Some(modules)) = (cells.next(), cells.next()) else {
            continue;
        };
        let Ok(n) = n.trim().parse::<u32>() else {
            continue;
        };
        for name in modules.split(", ") {
            documented.push((name.trim().trim_matches('`').to_owned(), n));
        }
    }
    let mut checked: Vec<(String, u32)> = LAYERS
        .iter()
        .filter(|(m, _)| *m != "testing")
        .map(|(m, l)| (m.to_string(), *l))
        .collect();
    documented.sort();
    checked.sort();
    assert_eq!(documented, checked);
}
