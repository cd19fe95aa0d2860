//! Older settings files still load: keys that moved to another section since are moved
//! before the settings are read (serde's `alias` renames a field within its struct; these
//! cross sections). Each move names the issue that made it.

/// (old path, new path), dotted. Issue 38: frame-wide settings left the tree samplers'
/// `[sampling]` for `[frame]`.
pub const MOVED: &[(&str, &str)] = &[
    ("sampling.accumulate", "frame.accumulate"),
    ("sampling.fixed_seed", "frame.fixed_seed"),
];

/// Moves every key of [`MOVED`] found in `root` to its new place. A key set at both places
/// is an error naming both (which one to keep is the user's call).
pub fn migrate(root: &mut toml::Table) -> Result<(), String> {
    for (old, new) in MOVED {
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
        if t.contains_key(leaf) {
            return Err(format!(
                "{old} and {new} are both set: {old} is the older name of {new}; keep one"
            ));
        }
        t.insert(leaf.to_string(), v);
    }
    Ok(())
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

    #[test]
    fn moved_keys_land_in_their_new_section_and_a_clash_is_named() {
        let mut t: toml::Table =
            toml::from_str("[sampling]\naccumulate = true\ncut_size = 8\n[frame]\n").unwrap();
        migrate(&mut t).unwrap();
        assert_eq!(t["frame"]["accumulate"].as_bool(), Some(true));
        assert_eq!(t["sampling"]["cut_size"].as_integer(), Some(8));
        assert!(t["sampling"].get("accumulate").is_none());
        let mut only: toml::Table = toml::from_str("[sampling]\nfixed_seed = true").unwrap();
        migrate(&mut only).unwrap();
        assert!(!only.contains_key("sampling"), "an emptied section goes");
        let mut both: toml::Table =
            toml::from_str("[sampling]\nfixed_seed = true\n[frame]\nfixed_seed = false").unwrap();
        let e = migrate(&mut both).unwrap_err();
        assert!(
            e.contains("frame.fixed_seed") && e.contains("frame.fixed_seed"),
            "{e}"
        );
    }
}
