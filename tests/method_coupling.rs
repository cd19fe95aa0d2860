//! How far a GI method is from being "one folder plus one registry line" (issue 38): for each
//! method module (`src/methods/<folder>/`), the source files outside its folder that name it
//! in code. Run it to see the table:
//!
//!     cargo test --release --test method_coupling -- --nocapture
//!
//! What counts as naming a module `m` (comments stripped): a path through the registry's
//! module (`methods::m`, `methods::{.., m, ..}`, or `super::m` from a sibling under
//! `src/methods/`), one of the module's own type names in code, not in a string literal (a `pub struct` / `enum` / `trait` /
//! `type` defined only in its folder, re-exports included), or one of its methods' CLI ids as
//! a string literal (but for ids that are common values, `SHARED_WORDS`). The registry file (`src/methods/mod.rs`) is reported apart: its lines are
//! the registry.
//!
//! The test holds each module to its count (a ratchet: it may fall, never grow); lower the
//! numbers in `LIMITS` when a change moves code home.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Files outside its folder (registry file excluded) that may name each module today.
const LIMITS: &[(&str, usize)] = &[
    ("direct_only", 0),
    ("ground_truth", 1),
    ("light_culling", 1),
    ("lightcut_interpolation", 1),
    // Of these, five are Lightcut Interpolation's files, which build on Lightcuts' build and
    // cut kernels (`lightcuts/kernels.rs`) and compare with Lightcuts in their figure.
    ("lightcuts", 7),
    ("reference", 0),
    ("restir", 0),
    ("tree_samplers", 6),
    ("val", 0),
];

/// Method ids that are also other settings' values ("off": the temporal stage's mode, a
/// view's false colour): as string literals they name no method.
const SHARED_WORDS: &[&str] = &["off"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<_> = rd.filter_map(|e| e.ok()).map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The text with `//` and `/* */` comments blanked (string literals kept; line numbers kept).
fn strip_comments(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let mut in_str = false;
    while i < b.len() {
        let c = b[i] as char;
        if in_str {
            out.push(c);
            if c == '\\' && i + 1 < b.len() {
                out.push(b[i + 1] as char);
                i += 2;
                continue;
            }
            if c == '"' {
                in_str = false;
            }
            i += 1;
        } else if c == '"' {
            in_str = true;
            out.push(c);
            i += 1;
        } else if c == '\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            // A char literal ('"', '\n'): copied whole so its quote opens no string.
            let end = text[i + 1..].find('\'').map_or(b.len(), |k| i + 1 + k + 1);
            let end = if b[i + 1] == b'\\' {
                text[i + 2..].find('\'').map_or(b.len(), |k| i + 2 + k + 1)
            } else {
                end
            };
            out.push_str(&text[i..end]);
            i = end;
        } else if text[i..].starts_with("//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if text[i..].starts_with("/*") {
            let end = text[i + 2..].find("*/").map_or(b.len(), |k| i + 2 + k + 2);
            for ch in text[i..end].chars() {
                if ch == '\n' {
                    out.push('\n');
                }
            }
            i = end;
        } else {
            let ch = text[i..].chars().next().unwrap_or(' ');
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Whether `word` occurs in `line` as a whole identifier.
fn has_word(line: &str, word: &str) -> bool {
    let mut from = 0;
    while let Some(k) = line[from..].find(word) {
        let s = from + k;
        let e = s + word.len();
        let before = line[..s].chars().next_back().is_none_or(|c| !is_ident(c));
        let after = line[e..].chars().next().is_none_or(|c| !is_ident(c));
        if before && after {
            return true;
        }
        from = e;
    }
    false
}

/// The names a `methods::{...}` group imports at its top level (nested groups flattened).
fn group_names(code: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(k) = code[from..].find("methods::{") {
        let open = from + k + "methods::".len();
        let mut depth = 0;
        let mut end = open;
        for (j, c) in code[open..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + j;
                        break;
                    }
                }
                _ => {}
            }
        }
        let line = code[..open].matches('\n').count() + 1;
        let inner = &code[open + 1..end.max(open + 1)];
        let mut depth = 0;
        let mut cur = String::new();
        for c in inner.chars() {
            if c == '{' || c == '}' {
                depth += if c == '{' { 1 } else { -1 };
            } else if depth == 0 && (c == ',' || c == ':' || c.is_whitespace()) {
                // A separator (comma, space, `::`) ends a name.
                if !cur.is_empty() {
                    out.push((line, std::mem::take(&mut cur)));
                }
            } else if depth == 0 {
                cur.push(c);
            }
        }
        if !cur.is_empty() {
            out.push((line, cur));
        }
        from = end.max(open + 1);
    }
    out
}

struct Module {
    folder: String,
    ids: Vec<String>,
    types: BTreeSet<String>,
}

fn modules(root: &Path) -> Vec<Module> {
    let methods = root.join("src/methods");
    let mut mods = Vec::new();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&methods)
        .expect("src/methods")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    let mut all = Vec::new();
    rust_files(&root.join("src"), &mut all);
    for d in dirs {
        let folder = d.file_name().unwrap().to_string_lossy().to_string();
        let mut files = Vec::new();
        rust_files(&d, &mut files);
        let mut ids = Vec::new();
        let mut types = BTreeSet::new();
        for f in &files {
            let text = strip_comments(&std::fs::read_to_string(f).unwrap());
            for part in text.split("MethodId::new(\"").skip(1) {
                if let Some(end) = part.find('"') {
                    ids.push(part[..end].to_string());
                }
            }
            for line in text.lines() {
                let t = line.trim_start();
                for kw in ["pub struct ", "pub enum ", "pub trait ", "pub type "] {
                    if let Some(rest) = t.strip_prefix(kw) {
                        let name: String = rest.chars().take_while(|c| is_ident(*c)).collect();
                        if name.len() >= 5 {
                            types.insert(name);
                        }
                    }
                }
            }
        }
        mods.push(Module { folder, ids, types });
    }
    // A type name defined outside the folder too is not the module's own.
    for f in &all {
        let text = strip_comments(&std::fs::read_to_string(f).unwrap());
        for m in &mut mods {
            if f.starts_with(methods.join(&m.folder)) {
                continue;
            }
            m.types.retain(|ty| {
                !["struct ", "enum ", "trait ", "type "].iter().any(|kw| {
                    text.lines()
                        .any(|l| has_word(l, ty) && l.contains(&format!("{kw}{ty}")))
                })
            });
        }
    }
    mods
}

/// Per module, per file outside its folder, the lines naming it and what they name.
type Table = BTreeMap<String, BTreeMap<String, Vec<String>>>;

/// The table and the modules it was made for.
fn coupling(root: &Path) -> (Table, Vec<Module>) {
    let mods = modules(root);
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    let mut table = Table::new();
    for f in &files {
        let rel = f.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
        let code = strip_comments(&std::fs::read_to_string(f).unwrap());
        // Paths and type names count in code only, not in string literals (a figure's
        // description naming "Lightcuts" is prose); ids count as string literals.
        let blank = blank_literals(&code);
        let blank_lines: Vec<&str> = blank.lines().collect();
        let groups = group_names(&blank);
        let in_methods = rel.starts_with("src/methods/");
        for m in &mods {
            if rel.starts_with(&format!("src/methods/{}/", m.folder)) {
                continue;
            }
            let mut hits = Vec::new();
            for (n, line) in code.lines().enumerate() {
                let mut what = Vec::new();
                let bare = blank_lines.get(n).copied().unwrap_or("");
                if bare.contains(&format!("methods::{}", m.folder)) && has_word(bare, &m.folder) {
                    what.push(format!("methods::{}", m.folder));
                }
                if in_methods && bare.contains(&format!("super::{}", m.folder)) && has_word(bare, &m.folder) {
                    what.push(format!("super::{}", m.folder));
                }
                for ty in &m.types {
                    if has_word(bare, ty) {
                        what.push(ty.clone());
                    }
                }
                for id in m.ids.iter().filter(|i| !SHARED_WORDS.contains(&i.as_str())) {
                    if line.contains(&format!("\"{id}\"")) {
                        what.push(format!("\"{id}\""));
                    }
                }
                if !what.is_empty() {
                    hits.push(format!("{}: {}", n + 1, what.join(", ")));
                }
            }
            for (n, name) in &groups {
                if *name == m.folder {
                    hits.push(format!("{n}: methods::{{{}}}", m.folder));
                }
            }
            if !hits.is_empty() {
                table
                    .entry(m.folder.clone())
                    .or_default()
                    .insert(rel.clone(), hits);
            }
        }
    }
    (table, mods)
}

#[test]
fn each_method_is_named_outside_its_folder_no_more_than_before() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (table, mods) = coupling(root);
    let mut over = Vec::new();
    println!("files outside a method's folder that name it in code (registry file apart):");
    for m in &mods {
        let files = table.get(&m.folder).cloned().unwrap_or_default();
        let outside: Vec<&String> = files.keys().filter(|f| *f != "src/methods/mod.rs").collect();
        let limit = LIMITS
            .iter()
            .find(|(n, _)| *n == m.folder)
            .map(|(_, l)| *l)
            .unwrap_or_else(|| panic!("add '{}' to LIMITS", m.folder));
        println!(
            "  {} ({} files, limit {limit}; ids {:?}):",
            m.folder,
            outside.len(),
            m.ids
        );
        for (f, hits) in &files {
            let tag = if f == "src/methods/mod.rs" {
                " [registry]"
            } else {
                ""
            };
            println!("    {f}{tag}: {}", hits.join("; "));
        }
        if outside.len() > limit {
            over.push(format!("{}: {} files > {limit}", m.folder, outside.len()));
        }
    }
    assert!(
        over.is_empty(),
        "a method is named in more files than before: {over:?}"
    );
}

#[test]
fn the_scan_finds_paths_groups_types_and_ids() {
    let code = strip_comments(
        "use crate::methods::{self, lightcuts::pass, val};\n// methods::val in a comment\nlet x = \"slc\"; /* methods::x */\n",
    );
    assert!(!code.contains("comment") && !code.contains("methods::x"));
    let g: Vec<String> = group_names(&code).into_iter().map(|(_, n)| n).collect();
    assert!(
        g.contains(&"lightcuts".to_string()) && g.contains(&"val".to_string()),
        "{g:?}"
    );
    assert!(has_word("a TreeSamplers b", "TreeSamplers") && !has_word("TreeSamplersX", "TreeSamplers"));
}

/// The shape issue 38 asks of the code outside tests, held as a ratchet (each count may fall,
/// never grow; lower `SHAPE_LIMITS` when a change improves one). Its goal: every count 0.
const SHAPE_LIMITS: &[(&str, usize)] = &[
    ("files over 700 lines", 0),
    ("functions over 150 lines", 0),
    ("too_many_arguments allows", 0),
    ("files in src/gpu and src/settings that name methods", 1),
    (
        "files in src/methods, src/gpu and src/settings that name crate::renderer",
        0,
    ),
    ("files below the app that name egui", 0),
];

/// The code with string and char literals' contents blanked (after [`strip_comments`]), so
/// that braces inside them count for nothing.
fn blank_literals(code: &str) -> String {
    let b = code.as_bytes();
    let mut out = String::with_capacity(code.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let raw_hashes = (c == b'r' && (i == 0 || !is_ident(b[i - 1] as char)))
            .then(|| b[i + 1..].iter().take_while(|&&h| h == b'#').count())
            .filter(|&n| b.get(i + 1 + n) == Some(&b'"'));
        if let Some(n) = raw_hashes {
            let close = format!("\"{}", "#".repeat(n));
            let start = i + 1 + n + 1;
            let end = code[start..]
                .find(&close)
                .map_or(b.len(), |k| start + k + close.len());
            out.push_str("r\"\"");
            out.extend(code[i..end].chars().filter(|&ch| ch == '\n'));
            i = end;
        } else if c == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            out.push_str("\"\"");
            out.extend(code[i..j.min(b.len())].chars().filter(|&ch| ch == '\n'));
            i = (j + 1).min(b.len());
        } else if c == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            let from = if b[i + 1] == b'\\' { i + 3 } else { i + 2 };
            let end = code[from..].find('\'').map_or(b.len(), |k| from + k + 1);
            out.push_str("' '");
            i = end;
        } else {
            let ch = code[i..].chars().next().unwrap_or(' ');
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// (name, first line, lines) of every `fn` with a body in `code` (literals blanked).
fn functions(code: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = code.lines().collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let Some(k) = l.find("fn ") else { continue };
        if k > 0 && is_ident(l[..k].chars().next_back().unwrap_or(' ')) {
            continue;
        }
        let name: String = l[k + 3..].chars().take_while(|&c| is_ident(c)).collect();
        if name.is_empty() {
            continue;
        }
        // The body: from the first `{` after the signature to its match (a `;` first: none).
        let mut depth = 0usize;
        let mut opened = false;
        'scan: for (j, line) in lines.iter().enumerate().skip(i) {
            let from = if j == i { k } else { 0 };
            for ch in line[from..].chars() {
                match ch {
                    ';' if !opened => break 'scan,
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' if opened => {
                        depth -= 1;
                        if depth == 0 {
                            out.push((name.clone(), i + 1, j - i + 1));
                            break 'scan;
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    out
}

/// The measures of [`SHAPE_LIMITS`] over `src/` (files named `*tests.rs` and everything from a
/// file's `#[cfg(test)]` on are tests), each with what it counted.
fn shape(root: &Path) -> BTreeMap<&'static str, Vec<String>> {
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    let mut m: BTreeMap<&'static str, Vec<String>> =
        SHAPE_LIMITS.iter().map(|(k, _)| (*k, Vec::new())).collect();
    for p in files {
        let rel = p
            .strip_prefix(root)
            .unwrap_or(&p)
            .to_string_lossy()
            .replace('\\', "/");
        if rel.ends_with("tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        let end = text.find("\n#[cfg(test)]").map_or(text.len(), |k| k + 1);
        let text = &text[..end];
        let n_lines = text.lines().count();
        let code = blank_literals(&strip_comments(text));
        let mut push = |k: &'static str, v: String| match m.get_mut(k) {
            Some(found) => found.push(v),
            None => panic!("'{k}' is not in SHAPE_LIMITS"),
        };
        if n_lines > 700 {
            push("files over 700 lines", format!("{rel} ({n_lines})"));
        }
        for (name, line, n) in functions(&code) {
            if n > 150 {
                push("functions over 150 lines", format!("{rel}:{line} {name} ({n})"));
            }
        }
        for (i, l) in code.lines().enumerate() {
            if l.contains("too_many_arguments") {
                push("too_many_arguments allows", format!("{rel}:{}", i + 1));
            }
        }
        if (rel.starts_with("src/gpu/") || rel.starts_with("src/settings/"))
            && code
                .lines()
                .any(|l| l.contains("methods::") || l.contains("crate::methods"))
        {
            push("files in src/gpu and src/settings that name methods", rel.clone());
        }
        if ["src/methods/", "src/gpu/", "src/settings/"]
            .iter()
            .any(|d| rel.starts_with(d))
            && code.lines().any(|l| l.contains("crate::renderer"))
        {
            push(
                "files in src/methods, src/gpu and src/settings that name crate::renderer",
                rel.clone(),
            );
        }
        let in_app = rel.starts_with("src/app/") || rel == "src/main.rs";
        let gui = [
            "egui",
            "egui_wgpu",
            "egui_plot",
            "egui_tiles",
            "eframe",
            "epaint",
            "ecolor",
        ];
        if !in_app && code.lines().any(|l| gui.iter().any(|w| has_word(l, w))) {
            push("files below the app that name egui", rel.clone());
        }
    }
    m
}

#[test]
fn the_code_keeps_its_shape_no_worse_than_before() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let m = shape(root);
    let mut over = Vec::new();
    for (k, limit) in SHAPE_LIMITS {
        let found = &m[k];
        println!("{k}: {} (limit {limit})", found.len());
        for f in found {
            println!("    {f}");
        }
        if found.len() > *limit {
            over.push(format!("{k}: {} > {limit}", found.len()));
        }
    }
    assert!(over.is_empty(), "the code's shape got worse: {over:?}");
}

#[test]
fn the_shape_scan_measures_bodies_not_literals() {
    let code = blank_literals(&strip_comments(
        "fn a() {\n    let s = \"{ not a brace\";\n    let c = '{';\n    let r = r#\"}\"#;\n}\nfn b();\npub fn c(x: u32) -> u32 {\n    x\n}\n",
    ));
    let f = functions(&code);
    assert_eq!(
        f,
        vec![("a".to_string(), 1, 5), ("c".to_string(), 7, 3)],
        "{code}"
    );
}
