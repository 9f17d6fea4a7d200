//! No two source files of any crate in the workspace import each other,
//! directly or around a loop: each file can be read knowing only the files
//! below it. A file's imports are the `crate::`, `super::`, `self::` and
//! child-module paths of its non-test code, each resolved to the file that
//! defines the item named (through re-exports, which are not imports of the
//! file that re-exports). Declaring a child module is not an import.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The crates checked, by the folder of their root file.
const CRATES: [(&str, &str); 7] = [
    (".", "src/lib.rs"),
    ("ofx-layer", "src/lib.rs"),
    ("ofx", "src/lib.rs"),
    ("harness", "src/lib.rs"),
    ("harness", "src/main.rs"),
    ("python", "src/lib.rs"),
    ("xtask", "src/main.rs"),
];

/// One crate's module tree: module path → file, and each file's code.
struct Crate {
    files: BTreeMap<Vec<String>, PathBuf>,
    code: HashMap<PathBuf, String>,
}

/// The code of a file without comments and without its test module.
fn non_test_code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let text = match text.find("#[cfg(test)]\nmod ") {
        Some(i) => &text[..i],
        None => &text[..],
    };
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The `mod name;` declarations of `code` (not inline modules).
fn child_modules(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in code.lines() {
        let l = line.trim_start();
        let l = l
            .strip_prefix("pub(crate) ")
            .or_else(|| l.strip_prefix("pub(super) "))
            .or_else(|| l.strip_prefix("pub "))
            .unwrap_or(l);
        if let Some(rest) = l.strip_prefix("mod ") {
            let name = ident_at(rest);
            if rest[name.len()..].trim_start().starts_with(';') {
                out.push(name.to_owned());
            }
        }
    }
    out
}

impl Crate {
    fn load(root: &Path) -> Crate {
        let mut c = Crate {
            files: BTreeMap::new(),
            code: HashMap::new(),
        };
        c.add(Vec::new(), root.to_path_buf());
        c
    }

    fn add(&mut self, module: Vec<String>, file: PathBuf) {
        let code = non_test_code(&file);
        let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let dir = if matches!(stem, "mod" | "lib" | "main") {
            file.parent().unwrap().to_path_buf()
        } else {
            file.with_extension("")
        };
        for child in child_modules(&code) {
            let flat = dir.join(format!("{child}.rs"));
            let nested = dir.join(&child).join("mod.rs");
            let path = if flat.is_file() { flat } else { nested };
            if path.is_file() {
                let mut m = module.clone();
                m.push(child);
                self.add(m, path);
            }
        }
        self.code.insert(file.clone(), code);
        self.files.insert(module, file);
    }

    /// Whether `file` defines an item called `name`.
    fn defines(&self, file: &Path, name: &str) -> bool {
        let code = &self.code[file];
        [
            "fn ", "struct ", "enum ", "trait ", "type ", "const ", "static ", "union ", "mod ",
        ]
        .iter()
        .any(|kw| {
            code.match_indices(kw).any(|(i, _)| {
                let before = code[..i].chars().last();
                before.is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_'))
                    && ident_at(&code[i + kw.len()..]) == name
            })
        }) || code.contains(&format!("macro_rules! {name}"))
    }

    /// The file that defines what `path` (segments after the start
    /// `base`) names, following re-exports.
    fn resolve(&self, base: &[String], path: &[String], depth: u32) -> Option<PathBuf> {
        let mut module = base.to_vec();
        let mut rest = path;
        while let Some(first) = rest.first() {
            let mut next = module.clone();
            next.push(first.clone());
            if !self.files.contains_key(&next) {
                break;
            }
            module = next;
            rest = &rest[1..];
        }
        let file = self.files.get(&module)?;
        let item = match rest.first() {
            Some(i) if i != "self" && i != "*" => i,
            _ => return Some(file.clone()),
        };
        if self.defines(file, item) || depth > 8 {
            return Some(file.clone());
        }
        // A re-export of the item: where it comes from.
        for u in uses(&self.code[file]) {
            if u.reexport
                && (u.path.last() == Some(item) || u.path.last().is_some_and(|l| l == "*"))
            {
                let (start, segs) = self.start_of(&module, &u.path)?;
                let mut segs = segs.to_vec();
                if segs.last().is_some_and(|l| l == "*") {
                    segs.pop();
                    segs.push(item.clone());
                }
                if let Some(f) = self.resolve(&start, &segs, depth + 1) {
                    return Some(f);
                }
            }
        }
        Some(file.clone())
    }

    /// Where a path used in `module` starts (`crate`, `super`, `self`, or a
    /// child module), and its remaining segments; `None` for other crates.
    fn start_of<'p>(
        &self,
        module: &[String],
        path: &'p [String],
    ) -> Option<(Vec<String>, &'p [String])> {
        let mut start = module.to_vec();
        let mut rest = path;
        match path.first().map(String::as_str) {
            Some("crate") => {
                start.clear();
                rest = &path[1..];
            }
            Some("self") => rest = &path[1..],
            Some("super") => {
                while rest.first().is_some_and(|s| s == "super") {
                    start.pop()?;
                    rest = &rest[1..];
                }
            }
            Some(first) => {
                let mut child = module.to_vec();
                child.push(first.to_owned());
                if !self.files.contains_key(&child) {
                    return None;
                }
            }
            None => return None,
        }
        Some((start, rest))
    }

    /// Every file each file imports.
    fn edges(&self) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
        let mut edges = BTreeMap::new();
        for (module, file) in &self.files {
            let mut to = BTreeSet::new();
            let code = &self.code[file];
            let paths = uses(code)
                .into_iter()
                .filter(|u| !u.reexport)
                .map(|u| u.path)
                .chain(inline_paths(code, &child_modules(code)));
            for path in paths {
                if let Some((start, rest)) = self.start_of(module, &path) {
                    if let Some(target) = self.resolve(&start, rest, 0) {
                        if &target != file {
                            to.insert(target);
                        }
                    }
                }
            }
            edges.insert(file.clone(), to);
        }
        edges
    }
}

/// One path of a `use` declaration, and whether it re-exports.
struct Use {
    path: Vec<String>,
    reexport: bool,
}

/// The paths of every `use` declaration in `code`, use trees expanded.
fn uses(code: &str) -> Vec<Use> {
    let mut out = Vec::new();
    for (at, end, reexport) in use_declarations(code) {
        let end = end - at;
        // `Name as Other` keeps `Name`: the renaming is marked before
        // white space goes.
        let tree: String = code[at + 4..at + end]
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
            .replace(" as ", "@")
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect();
        for path in expand(&tree) {
            let path: Vec<String> = path
                .split("::")
                .map(|s| s.split('@').next().unwrap_or(s).to_owned())
                .filter(|s| !s.is_empty())
                .collect();
            out.push(Use { path, reexport });
        }
    }
    out
}

/// Where each `use` declaration of `code` lies: from its `use` to its
/// `;`, and whether it re-exports (`pub use`, `pub(…) use`).
fn use_declarations(code: &str) -> Vec<(usize, usize, bool)> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = code[from..].find("use ") {
        let at = from + i;
        from = at + 4;
        let line_start = code[..at].rfind('\n').map_or(0, |n| n + 1);
        let head = code[line_start..at].trim();
        let reexport = head == "pub"
            || (head.starts_with("pub(") && head.ends_with(')') && !head.contains(' '));
        if !(head.is_empty() || reexport) {
            continue;
        }
        let Some(end) = code[at..].find(';') else {
            break;
        };
        out.push((at, at + end, reexport));
        from = at + end;
    }
    out
}

/// `a::{b, c::{d, e}}` as `a::b`, `a::c::d`, `a::c::e`.
fn expand(tree: &str) -> Vec<String> {
    let Some(open) = tree.find('{') else {
        return vec![tree.to_owned()];
    };
    let prefix = &tree[..open];
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.is_empty())
        .flat_map(expand)
        .map(|p| format!("{prefix}{p}"))
        .collect()
}

/// Paths written in code outside `use` declarations, wherever they stand
/// (a field's type, a call, an expression): `crate::a::b`, `super::x`,
/// `self::y`, and `child::z` for each of the file's child modules.
fn inline_paths(code: &str, children: &[String]) -> Vec<Vec<String>> {
    let declarations = use_declarations(code);
    let in_use = |i: usize| declarations.iter().any(|&(a, b, _)| (a..b).contains(&i));
    let starts = ["crate", "super", "self"]
        .into_iter()
        .chain(children.iter().map(String::as_str))
        .map(|s| format!("{s}::"));
    let mut out = Vec::new();
    for start in starts {
        for (i, _) in code.match_indices(&start) {
            let before = code[..i].chars().last();
            if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            if in_use(i) {
                continue;
            }
            let mut segs = Vec::new();
            let mut rest = &code[i..];
            loop {
                let id = ident_at(rest);
                if id.is_empty() {
                    break;
                }
                segs.push(id.to_owned());
                rest = &rest[id.len()..];
                match rest.strip_prefix("::") {
                    Some(r) => rest = r,
                    None => break,
                }
            }
            out.push(segs);
        }
    }
    out
}

/// The groups of files that import each other around a loop (Tarjan).
fn cycles(edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct State<'a> {
        edges: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: HashMap<&'a PathBuf, usize>,
        low: HashMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on_stack: BTreeSet<&'a PathBuf>,
        found: Vec<Vec<PathBuf>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a PathBuf) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                group.push(w.clone());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                s.found.push(group);
            }
        }
    }
    let mut s = State {
        edges,
        index: HashMap::new(),
        low: HashMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.found
}

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_source_files_import_each_other_in_any_crate() {
    let mut found = Vec::new();
    let mut imports = 0;
    for (dir, root) in CRATES {
        let c = Crate::load(&workspace().join(dir).join(root));
        let edges = c.edges();
        imports += edges.values().map(BTreeSet::len).sum::<usize>();
        found.extend(cycles(&edges).into_iter().map(|g| describe(&g, &edges)));
    }
    assert!(imports > 300, "the scan found the imports ({imports})");
    assert!(found.is_empty(), "import cycles:\n{}", found.join("\n"));
}

/// A loop's files and, under them, which of them imports which: what to
/// cut to break it.
fn describe(group: &[PathBuf], edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> String {
    let name = |p: &PathBuf| {
        let p = p.strip_prefix(workspace()).unwrap_or(p);
        p.display().to_string()
    };
    let mut text = group.iter().map(name).collect::<Vec<_>>().join(" <-> ");
    for from in group {
        for to in edges[from].iter().filter(|t| group.contains(t)) {
            text += &format!("\n    {} imports {}", name(from), name(to));
        }
    }
    text
}

/// The scan resolves what it must: a sibling import, a re-exported item
/// followed to its defining file, paths in a public field and through a
/// child module, and a known two-file loop in a made-up
/// crate found as one.
#[test]
fn the_scan_resolves_imports_and_finds_a_loop() {
    let dir = std::env::temp_dir().join(format!("morphfx-cycles-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("a")).unwrap();
    let write = |p: &str, s: &str| std::fs::write(dir.join(p), s).unwrap();
    write("lib.rs", "mod a;\nmod c;\nmod d;\npub use a::Thing;\n");
    write("a/mod.rs", "mod x;\nmod y;\npub use x::Thing;\n");
    write("a/x.rs", "use super::y::helper;\npub struct Thing;\n");
    write(
        "a/y.rs",
        "pub fn helper() {}\nfn f() { let _ = crate::Thing; }\n",
    );
    write("c.rs", "use crate::a::Thing;\npub struct Q;\n");
    // Paths outside `use`: a public field's type, a bare child module.
    std::fs::create_dir_all(dir.join("d")).unwrap();
    write(
        "d/mod.rs",
        "mod e;\npub struct S {\n    pub f: super::c::Q,\n}\nfn g() { e::run(); }\n",
    );
    write("d/e.rs", "pub fn run() {}\n");
    let c = Crate::load(&dir.join("lib.rs"));
    let edges = c.edges();
    let e = |from: &str, to: &str| edges[&dir.join(from)].contains(&dir.join(to));
    assert!(e("a/x.rs", "a/y.rs"));
    assert!(e("a/y.rs", "a/x.rs"), "crate::Thing is defined in a/x.rs");
    assert!(e("c.rs", "a/x.rs"));
    assert!(!e("lib.rs", "a/x.rs"), "a re-export is not an import");
    assert!(e("d/mod.rs", "c.rs"), "a field's type is an import");
    assert!(
        e("d/mod.rs", "d/e.rs"),
        "a call through a child module is one"
    );
    let found = cycles(&edges);
    assert_eq!(found, vec![vec![dir.join("a/x.rs"), dir.join("a/y.rs")]]);
    let _ = std::fs::remove_dir_all(&dir);
}
