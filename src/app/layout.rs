//! The workbench's tiles: which panes exist, the preset arrangements, and the persisted tree
//! (`egui_tiles`, the crate rerun's viewer uses). What a pane draws lives with the pane's
//! code; this file only says where panes go.

use egui_tiles::{Container, Linear, LinearDir, Tile, TileId, Tiles, Tree};

/// One pane of the workbench.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Pane {
    /// The progressive render (click to pick, drag to orbit or move the selected object).
    Viewport,
    /// The unit sphere at the picked point, in 3D.
    Sphere,
    /// The hemisphere seen from the normal (Nusselt's disk: areas are form factors).
    Hemisphere,
    /// The set difference in the occluder's projection plane, Greiner–Hormann phase by phase.
    Planar,
    /// The stepper through 000 Alg. 1, with the lesson text of the current stage.
    Stages,
    /// The numbers of the picked point.
    Numbers,
    /// Method, sampling and display settings.
    Settings,
    /// The objects of the scene: select, move, undo, save.
    Scene,
    /// The structure of the selected light: its BSP tree of silhouettes.
    LightStructure,
    /// Bench reports and the error trace against a reference.
    Plots,
    /// The environment light (paper 002).
    Environment,
}

impl Pane {
    pub const ALL: [Pane; 11] = [
        Pane::Viewport,
        Pane::Sphere,
        Pane::Hemisphere,
        Pane::Planar,
        Pane::Stages,
        Pane::Numbers,
        Pane::Settings,
        Pane::Scene,
        Pane::LightStructure,
        Pane::Plots,
        Pane::Environment,
    ];

    /// A picture rather than a form: it can be maximised.
    pub(crate) fn is_view(self) -> bool {
        matches!(
            self,
            Pane::Viewport | Pane::Sphere | Pane::Hemisphere | Pane::Planar | Pane::Plots
        )
    }

    pub(crate) fn title(self) -> &'static str {
        match self {
            Pane::Viewport => "Viewport",
            Pane::Sphere => "Sphere",
            Pane::Hemisphere => "Hemisphere",
            Pane::Planar => "Projected plane",
            Pane::Stages => "Stages",
            Pane::Numbers => "Numbers",
            Pane::Settings => "Render",
            Pane::Scene => "Scene",
            Pane::LightStructure => "Light structure",
            Pane::Plots => "Plots",
            Pane::Environment => "Environment",
        }
    }
}

/// A preset arrangement of the panes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Preset {
    /// Settings and scene at the left, the viewport, the sphere above the stages at the right.
    Explore,
    /// The viewport and a large sphere side by side, the lesson beside them.
    Teach,
    /// The viewport beside the plots of a bench run.
    Benchmark,
}

impl Preset {
    pub const ALL: [Preset; 3] = [Preset::Explore, Preset::Teach, Preset::Benchmark];

    pub fn name(self) -> &'static str {
        match self {
            Preset::Explore => "explore",
            Preset::Teach => "teach",
            Preset::Benchmark => "benchmark",
        }
    }

    pub fn from_name(s: &str) -> Option<Preset> {
        Preset::ALL.into_iter().find(|p| p.name() == s)
    }

    /// The tree of this preset. Shares are fractions of the parent's size; at the default
    /// 1280×800 window they give the sphere at least 400 px in `explore` and `teach`
    /// (checked by `tests/workbench_layout.rs`).
    pub(crate) fn tree(self) -> Tree<Pane> {
        let mut t = Tiles::default();
        let root = match self {
            Preset::Explore => {
                let left = tabs(
                    &mut t,
                    &[
                        Pane::Settings,
                        Pane::Scene,
                        Pane::Environment,
                        Pane::LightStructure,
                    ],
                );
                let view = t.insert_pane(Pane::Viewport);
                let sphere = tabs(&mut t, &[Pane::Sphere, Pane::Hemisphere, Pane::Planar]);
                let below = tabs(&mut t, &[Pane::Stages, Pane::Numbers, Pane::Plots]);
                let right = linear(
                    &mut t,
                    LinearDir::Vertical,
                    &[(sphere, 0.64), (below, 0.36)],
                );
                linear(
                    &mut t,
                    LinearDir::Horizontal,
                    &[(left, 0.21), (view, 0.41), (right, 0.38)],
                )
            }
            Preset::Teach => {
                let view = t.insert_pane(Pane::Viewport);
                let sphere = tabs(&mut t, &[Pane::Sphere, Pane::Hemisphere, Pane::Planar]);
                let lesson = tabs(&mut t, &[Pane::Stages, Pane::Numbers, Pane::Scene]);
                let side = tabs(&mut t, &[Pane::Settings, Pane::Environment]);
                let right = linear(&mut t, LinearDir::Vertical, &[(lesson, 0.72), (side, 0.28)]);
                linear(
                    &mut t,
                    LinearDir::Horizontal,
                    &[(view, 0.36), (sphere, 0.40), (right, 0.24)],
                )
            }
            Preset::Benchmark => {
                let left = tabs(&mut t, &[Pane::Settings, Pane::Scene, Pane::Environment]);
                let view = t.insert_pane(Pane::Viewport);
                let plots = t.insert_pane(Pane::Plots);
                let below = tabs(
                    &mut t,
                    &[Pane::Numbers, Pane::Sphere, Pane::Hemisphere, Pane::Stages],
                );
                let right = linear(&mut t, LinearDir::Vertical, &[(plots, 0.55), (below, 0.45)]);
                linear(
                    &mut t,
                    LinearDir::Horizontal,
                    &[(left, 0.2), (view, 0.42), (right, 0.38)],
                )
            }
        };
        let mut tree = Tree::new(egui::Id::unique("penumbra_tiles"), root, t);
        // Panes a preset leaves out stay reachable: `View > Panes` shows them again.
        add_missing_panes(&mut tree);
        tree
    }
}

fn tabs(t: &mut Tiles<Pane>, panes: &[Pane]) -> TileId {
    let ids = panes.iter().map(|p| t.insert_pane(*p)).collect();
    t.insert_tab_tile(ids)
}

fn linear(t: &mut Tiles<Pane>, dir: LinearDir, children: &[(TileId, f32)]) -> TileId {
    let mut l = Linear::new(dir, children.iter().map(|c| c.0).collect());
    for &(id, share) in children {
        l.shares.set_share(id, share);
    }
    t.insert_container(Container::Linear(l))
}

/// The tile of `pane`, if the tree has it.
pub(crate) fn find(tree: &Tree<Pane>, pane: Pane) -> Option<TileId> {
    tree.tiles.find_pane(&pane)
}

/// Adds every pane the tree lacks, hidden, to the root container (a persisted tree from an
/// older version, or a preset that leaves a pane out), so that every pane can be shown.
pub(crate) fn add_missing_panes(tree: &mut Tree<Pane>) {
    let Some(root) = tree.root() else {
        *tree = Preset::Explore.tree();
        return;
    };
    for pane in Pane::ALL {
        if find(tree, pane).is_none() {
            let id = tree.tiles.insert_pane(pane);
            tree.tiles.set_visible(id, false);
            if let Some(Tile::Container(c)) = tree.tiles.get_mut(root) {
                c.add_child(id);
            }
        }
    }
}

/// Shows `pane` (making it visible and the active tab of its container).
pub fn reveal(tree: &mut Tree<Pane>, pane: Pane) {
    if let Some(id) = find(tree, pane) {
        tree.tiles.set_visible(id, true);
        tree.make_active(|tid, _| tid == id);
    }
}

/// Whether `pane` is drawn this frame (visible, and the active tab where it is a tab).
pub fn is_shown(tree: &Tree<Pane>, pane: Pane) -> bool {
    find(tree, pane).is_some_and(|id| tree.active_tiles().contains(&id))
}
