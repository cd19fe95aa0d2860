//! Older settings files still load: keys that moved to another section since are moved
//! before the settings are read (serde's `alias` renames a field within its struct; these
//! cross sections). Each move names the issue that made it.

/// (old path, new path), dotted, of the frame's own settings: applied first. Issue 38:
/// frame-wide settings left the tree samplers' `[sampling]` for `[frame]`.
pub const MOVED: &[(&str, &str)] = &[
    ("sampling.accumulate", "frame.accumulate"),
    ("sampling.fixed_seed", "frame.fixed_seed"),
];

/// A key a method moved into its own `[methods.*]` table, registered in the method's folder
/// (`inventory::submit!`): the tree samplers' `[sampling]` became `[methods.slc]`.
pub struct Moved {
    pub old: &'static str,
    pub new: &'static str,
}

inventory::collect!(Moved);

/// Every move, the frame's first, then the methods'.
fn moves() -> impl Iterator<Item = (&'static str, &'static str)> {
    MOVED
        .iter()
        .copied()
        .chain(inventory::iter::<Moved>.into_iter().map(|m| (m.old, m.new)))
}

/// A dotted key as written today (`--set sampling.fixed_seed=true` sets `frame.fixed_seed`).
pub fn rename_path(key: &str) -> String {
    for (old, new) in moves() {
        if key == old {
            return new.to_string();
        }
        if let Some(rest) = key.strip_prefix(old).and_then(|r| r.strip_prefix('.')) {
            return format!("{new}.{rest}");
        }
    }
    key.to_string()
}

/// Moves every key of [`MOVED`] found in `root` to its new place. A key set at both places
/// is an error naming both (which one to keep is the user's call).
pub fn migrate(root: &mut toml::Table) -> Result<(), String> {
    for (old, new) in moves() {
        let Some(v) = take(root, old) else { continue };
        let (parent, leaf) = new.rsplit_once('.').unwrap_or(("", new));
        let mut t = &mut *root;
        for p in parent.split('.').filter(|p| !p.is_empty()) {
            t = t
                .entry(p.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                .as_table_mut()
                .ok_or_else(|| format!("{p} is a value, not a table"))?;
        }
        match t.get_mut(leaf) {
            None => {
                t.insert(leaf.to_string(), v);
            }
            Some(now) => merge(now, v, old, new)?,
        }
    }
    Ok(())
}

/// Merges the old table `v` into the new one (`now`); a key set in both is an error.
fn merge(now: &mut toml::Value, v: toml::Value, old: &str, new: &str) -> Result<(), String> {
    match (now.as_table_mut(), v) {
        (Some(dst), toml::Value::Table(src)) => {
            for (k, x) in src {
                match dst.get_mut(&k) {
                    None => {
                        dst.insert(k, x);
                    }
                    Some(y) => merge(y, x, &format!("{old}.{k}"), &format!("{new}.{k}"))?,
                }
            }
            Ok(())
        }
        _ => Err(format!(
            "{old} and {new} are both set: {old} is the older name of {new}; keep one"
        )),
    }
}

/// Removes the dotted `path` from `root` (and a table it leaves empty), returning its value.
fn take(root: &mut toml::Table, path: &str) -> Option<toml::Value> {
    match path.split_once('.') {
        None => root.remove(path),
        Some((head, rest)) => {
            let sub = root.get_mut(head)?.as_table_mut()?;
            let v = take(sub, rest);
            if sub.is_empty() {
                root.remove(head);
            }
            v
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // A method's move, as a method's folder registers one.
    inventory::submit! { Moved { old: "knobs", new: "methods.demo" } }

    #[test]
    fn moved_keys_land_in_their_new_section_and_a_clash_is_named() {
        let mut t: toml::Table =
            toml::from_str("[sampling]\naccumulate = true\n[frame]\n[knobs]\ncap = 8\n[knobs.inner]\nn = 2")
                .unwrap();
        migrate(&mut t).unwrap();
        assert_eq!(t["frame"]["accumulate"].as_bool(), Some(true));
        assert!(!t.contains_key("sampling"), "an emptied section goes");
        assert!(!t.contains_key("knobs"));
        assert_eq!(t["methods"]["demo"]["cap"].as_integer(), Some(8));
        assert_eq!(t["methods"]["demo"]["inner"]["n"].as_integer(), Some(2));
        // Old and new halves of one table merge; the same key in both is named.
        let mut halves: toml::Table = toml::from_str("[knobs]\ncap = 8\n[methods.demo]\nlimit = 4").unwrap();
        migrate(&mut halves).unwrap();
        assert_eq!(halves["methods"]["demo"]["cap"].as_integer(), Some(8));
        assert_eq!(halves["methods"]["demo"]["limit"].as_integer(), Some(4));
        let mut twice: toml::Table = toml::from_str("[knobs]\ncap = 8\n[methods.demo]\ncap = 4").unwrap();
        let e = migrate(&mut twice).unwrap_err();
        assert!(e.contains("knobs.cap") && e.contains("methods.demo.cap"), "{e}");
        let mut both: toml::Table =
            toml::from_str("[sampling]\nfixed_seed = true\n[frame]\nfixed_seed = false").unwrap();
        let e = migrate(&mut both).unwrap_err();
        assert!(
            e.contains("sampling.fixed_seed") && e.contains("frame.fixed_seed"),
            "{e}"
        );
        assert_eq!(rename_path("knobs.inner.n"), "methods.demo.inner.n");
        assert_eq!(rename_path("sampling.fixed_seed"), "frame.fixed_seed");
        assert_eq!(rename_path("knobsx.n"), "knobsx.n");
    }
}
