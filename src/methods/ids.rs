//! Method and view identities: [`MethodId`] (a method's CLI name) and [`MethodView`] (a method
//! view's name), their serde spellings, and the registry's lists of them.

use super::*;

/// A method's identity: its CLI name (`render --method <cli>`), stable across versions.
/// Settings files store it as that string (the older enum spellings `Slc`, `GroundTruth`, ...
/// are accepted when read).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct MethodId(&'static str);

impl MethodId {
    pub const fn new(cli: &'static str) -> Self {
        Self(cli)
    }
    /// The name on the command line and in settings files.
    pub fn cli(self) -> &'static str {
        self.0
    }
    /// Its registry entry (every id in use comes from the registry; an id that is not
    /// registered falls back to the first method's entry).
    pub fn info(self) -> &'static MethodInfo {
        REGISTRY
            .iter()
            .copied()
            .find(|m| m.id == self)
            .unwrap_or(REGISTRY[0])
    }
    /// The label the GUI shows.
    pub fn name(self) -> &'static str {
        self.info().label
    }
    pub fn kind(self) -> Kind {
        self.info().kind
    }
    /// Per-frame estimators (compared with the ground truth, timed at equal time).
    pub fn per_frame(self) -> bool {
        self.kind() == Kind::PerFrame
    }
    /// The tree samplers (SLC, SST, RTSLC): one estimate per frame from the light tree, with
    /// the traversal diagnostics and the pixel story.
    pub fn samples_tree(self) -> bool {
        self.info().module.name == tree_samplers::MODULE.name
    }
    /// Whether it runs on the radix tree too ([`Resource::AnyTree`]).
    pub fn any_tree(self) -> bool {
        self.info().reads.contains(&Resource::AnyTree)
    }
    /// The tree a frame of this method builds when `wanted` is asked for: `wanted` (the
    /// overlay and the statistics show it), unless the method needs the perfect tree (it
    /// reads the tree but not through its links).
    pub fn tree_kind(self, wanted: crate::base::sst_node::TreeKind) -> crate::base::sst_node::TreeKind {
        if self.refuses_tree(wanted).is_some() {
            crate::base::sst_node::TreeKind::Perfect
        } else {
            wanted
        }
    }
    /// The refusal of `tree.kind = lbvh` for a method that reads the tree without its links
    /// (the CLI's message); None where the method takes either tree or no tree at all.
    pub fn refuses_tree(self, wanted: crate::base::sst_node::TreeKind) -> Option<String> {
        let reads_tree = self.info().reads.contains(&Resource::Tree);
        (wanted != crate::base::sst_node::TreeKind::Perfect && reads_tree && !self.any_tree()).then(|| {
            let serves: Vec<&str> = REGISTRY
                .iter()
                .filter(|m| m.reads.contains(&Resource::AnyTree))
                .map(|m| m.id.cli())
                .collect();
            format!(
                "tree {}: {} runs on the perfect tree only (the radix tree serves {})",
                wanted.name(),
                self.info().label,
                serves.join(", ")
            )
        })
    }
    /// The refusal of `vpl.bounces > 1` for a method that renders the RSM's first bounce only
    /// (the CLI's message); None where the method shades the frame's VPLs of every bounce.
    pub fn refuses_bounces(self, bounces: u32) -> Option<String> {
        (bounces > 1 && self.info().one_bounce).then(|| {
            format!(
                "vpl.bounces {bounces}: {} lights the scene from the RSM's texels (one bounce); use vpl.bounces = 1",
                self.info().label
            )
        })
    }
    /// The BRDF a frame of this method shades with: `wanted`, or Lambert where it refuses
    /// it (the GUI says so; the direct light and the comparison's truth follow).
    pub fn brdf(self, wanted: crate::settings::Brdf) -> crate::settings::Brdf {
        if self.refuses_brdf(wanted).is_some() {
            crate::settings::Brdf::Lambert
        } else {
            wanted
        }
    }
    /// The refusal of `gi.brdf = ggx` for a method that shades with Lambert only (the tree
    /// samplers' own limits, half resolution and interleaving, are in their `validate`).
    pub fn refuses_brdf(self, brdf: crate::settings::Brdf) -> Option<String> {
        (brdf != crate::settings::Brdf::Lambert && !self.info().glossy).then(|| {
            let glossy: Vec<&str> = REGISTRY
                .iter()
                .filter(|m| m.glossy && m.kind != Kind::DirectOnly)
                .map(|m| m.short)
                .collect();
            format!(
                "brdf {}: {} shades with Lambert only so far (GGX: {} and the direct light)",
                brdf.name(),
                self.info().label,
                glossy.join(", ")
            )
        })
    }
    /// The method named `name` on the command line or in a settings file (case-insensitive;
    /// `-` and `_` ignored, so `ground-truth`, `GroundTruth` and `ground_truth` are one).
    pub fn parse(name: &str) -> Result<MethodId, String> {
        let norm = |s: &str| {
            s.chars()
                .filter(|c| *c != '-' && *c != '_' && !c.is_whitespace())
                .flat_map(char::to_lowercase)
                .collect::<String>()
        };
        let want = norm(name);
        REGISTRY
            .iter()
            .find(|m| norm(m.id.cli()) == want || m.aliases.iter().any(|a| norm(a) == want))
            .map(|m| m.id)
            .ok_or_else(|| {
                format!(
                    "unknown GI method '{name}'; the methods are: {}",
                    cli_names().join(", ")
                )
            })
    }
}

impl Default for MethodId {
    /// The thesis's method: the workbench opens on it and `render` renders it.
    fn default() -> Self {
        tree_samplers::SLC
    }
}

impl fmt::Debug for MethodId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

impl fmt::Display for MethodId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

impl Serialize for MethodId {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.0)
    }
}

impl<'de> Deserialize<'de> for MethodId {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        MethodId::parse(&s).map_err(serde::de::Error::custom)
    }
}

/// The CLI names of every registered method.
pub fn cli_names() -> Vec<&'static str> {
    REGISTRY.iter().map(|m| m.id.cli()).collect()
}

/// The per-frame methods (what `results` and the sheets compare), in registry order.
pub fn per_frame() -> Vec<MethodId> {
    REGISTRY
        .iter()
        .filter(|m| m.kind == Kind::PerFrame)
        .map(|m| m.id)
        .collect()
}

/// The methods a comparison sheet can show as columns (not the truth it compares against,
/// not direct light only), in registry order.
pub fn sheet_columns() -> Vec<MethodId> {
    REGISTRY
        .iter()
        .filter(|m| !m.truth_of_vpls && m.kind != Kind::DirectOnly)
        .map(|m| m.id)
        .collect()
}

/// The method the comparison views, `--compare-gt`, sheets and the harness measure against:
/// the ground truth of the frame's own VPLs.
pub fn comparison_truth() -> MethodId {
    REGISTRY
        .iter()
        .find(|m| m.truth_of_vpls)
        .map_or(ground_truth::ID, |m| m.id)
}

/// The method modules (methods that share a module share one GPU instance), each once.
pub fn modules() -> Vec<&'static Module> {
    let mut v: Vec<&'static Module> = Vec::new();
    for m in REGISTRY {
        if !v.iter().any(|x| x.name == m.module.name) {
            v.push(m.module);
        }
    }
    v
}

/// Checks every registered method's settings (each names the field it refuses).
pub fn validate_all(s: &RenderSettings) -> Result<(), String> {
    for m in REGISTRY {
        (m.validate)(s)?;
    }
    Ok(())
}

/// The settings table `id` reads as it reads it: its own `[methods.*]` section (declared by
/// `MethodInfo::fields`, the tree samplers' shared by the three) with the defaults filled in
/// where the settings leave a key out; None for a method without a table of its own.
pub fn own_settings(id: MethodId, s: &RenderSettings) -> Option<(String, toml::Table)> {
    let own = (id.info().fields)()
        .into_iter()
        .find(|f| f.table.is_some() && f.section.starts_with("methods."))?;
    let key = own.section.strip_prefix("methods.")?.to_string();
    let mut t = own.table.unwrap_or_default();
    if let Some(raw) = s.methods.raw(&key) {
        overlay(&mut t, raw);
    }
    Some((own.section, t))
}

/// Whether two settings configure the same frame: equal, each method's own table compared as
/// the method reads it (a table that spells a default out equals one that leaves it out).
pub fn same_settings(a: &RenderSettings, b: &RenderSettings) -> bool {
    let norm = |s: &RenderSettings| {
        let mut n = s.clone();
        for m in REGISTRY {
            if let Some((section, t)) = own_settings(m.id, s)
                && let Some(key) = section.strip_prefix("methods.")
            {
                n.methods.insert_raw(key, t);
            }
        }
        n
    };
    a == b || norm(a) == norm(b)
}

/// `over`'s keys written onto `base`, nested tables key by key.
fn overlay(base: &mut toml::Table, over: &toml::Table) {
    for (k, v) in over {
        match (base.get_mut(k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => overlay(b, o),
            _ => {
                base.insert(k.clone(), v.clone());
            }
        }
    }
}

/// A view a method draws beside final / direct / GI (the tree samplers' traversal steps, ...).
pub struct ViewInfo {
    /// Its name in every buffer menu, in `--views` and in saved layouts (unique over the
    /// registry).
    pub name: &'static str,
    /// The file name (without extension) `render` writes it to.
    pub file: &'static str,
    /// What it shows (the buffer menu's hover text).
    pub about: &'static str,
    /// The GPU passes whose output it shows (hovering one in the timings window shows it).
    pub passes: &'static [&'static str],
}

/// A method's view, by its [`ViewInfo::name`]: `ViewBuffer::Method(..)` in every view, A/B,
/// export and layout.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct MethodView(&'static str);

impl MethodView {
    pub const fn new(name: &'static str) -> Self {
        Self(name)
    }
    pub const fn name(self) -> &'static str {
        self.0
    }
    /// Its declaration and the first registered method that offers it.
    pub fn find(self) -> Option<(&'static ViewInfo, MethodId)> {
        REGISTRY
            .iter()
            .find_map(|m| m.views.iter().find(|v| v.name == self.0).map(|v| (v, m.id)))
    }
    /// Every method view of the registry, each once, in registry order.
    pub fn all() -> Vec<MethodView> {
        let mut v: Vec<MethodView> = Vec::new();
        for m in REGISTRY {
            for info in m.views {
                if !v.iter().any(|x| x.0 == info.name) {
                    v.push(MethodView(info.name));
                }
            }
        }
        v
    }
}

impl fmt::Debug for MethodView {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "MethodView({:?})", self.0)
    }
}

impl Serialize for MethodView {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.0)
    }
}

impl<'de> Deserialize<'de> for MethodView {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        MethodView::all()
            .into_iter()
            .find(|v| v.0 == s)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown method view '{s}'")))
    }
}
