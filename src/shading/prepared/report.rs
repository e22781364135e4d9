//! What preparing a scene found, as facts ([`PrepareNote`]): which path each mesh takes and
//! why, which trees were not built and why, which pairs no plane separates. Preparation
//! records them; the command line, the workbench and Python show them in the words of
//! [`PrepareNote`]'s `Display`, the one wording of each fact.

use super::mesh_path::PathKind;
use crate::shading::cost_model::TreeBudget;
use std::fmt;

/// Why a non-convex mesh got no tree of exact silhouettes.
#[derive(Clone, Debug, PartialEq)]
pub enum NoExactTree {
    /// More edges than a tree's point coding can name.
    TooManyEdges { max_edges: usize },
    /// The cost model found the windowed outline cheaper than any tree.
    WindowCheaper,
    /// The tree would have more leaves than its budget.
    OverBudget {
        budget: Option<TreeBudget>,
        limit: usize,
    },
}

/// One fact found while preparing a scene. `objects` name the object, or a group of instances
/// sharing one tree.
#[derive(Clone, Debug, PartialEq)]
pub enum PrepareNote {
    /// An object with no usable face: ignored.
    NoUsableFace { object: String },
    /// Flat up to the rounding of its coordinates: planar, its outline taken as one polygon.
    FlatUpToRounding { object: String, rounding: f64 },
    /// Convex up to the rounding of its coordinates: its convex hull stands in for it.
    ConvexUpToRounding {
        object: String,
        outside: f64,
        rounding: f64,
        hull_faces: usize,
        deviation: f64,
    },
    /// Not convex, with its topology.
    NotConvex {
        object: String,
        closed_manifold: bool,
        boundary_edges: u32,
        nonmanifold_edges: u32,
    },
    /// The scene builds no trees (and no library lends one).
    NoTreesBuilt { objects: Vec<String> },
    /// A convex mesh's tree would exceed its cells.
    ConvexTreeOverBudget {
        objects: Vec<String>,
        budget: Option<TreeBudget>,
        limit: usize,
    },
    /// A non-convex mesh got no tree.
    NoExactTree {
        objects: Vec<String>,
        why: NoExactTree,
    },
    /// Instances of one mesh share one tree, built in the first one's frame.
    SharedTree { objects: Vec<String> },
    /// A tree stays leaf-stored instead of hoisted.
    NotHoisted { objects: Vec<String>, error: String },
    /// A moved object's trees were dropped: its new vertices are not an affine image of its
    /// old ones.
    TreesDroppedByMove { object: String },
    /// The path a mesh takes.
    Path {
        object: String,
        faces: usize,
        path: PathKind,
    },
    /// No plane separates a light from an occluder.
    NotSeparated { light: String, occluder: String },
}

/// `'a', 'b', 'c'`.
fn quoted(objects: &[String]) -> String {
    let names: Vec<String> = objects.iter().map(|n| format!("'{n}'")).collect();
    names.join(", ")
}

/// The subject of a sentence about one object or a group of instances, and its possessive.
fn subject(objects: &[String]) -> (String, &'static str) {
    if objects.len() > 1 {
        (format!("objects {}", quoted(objects)), "their")
    } else {
        (format!("object {}", quoted(objects)), "its")
    }
}

/// Why a tree's budget is what it is, when the cost model (not the hard limit) set it.
fn budget_words(budget: &Option<TreeBudget>, limit: usize, units: &str) -> String {
    match budget {
        Some(b) if b.units < limit => format!(
            " (the cost model: at about {:.0} queries a tree saves about {:.2} s, which pays for \
             at most {} {units})",
            b.queries, b.saving_seconds, b.units
        ),
        _ => String::new(),
    }
}

impl fmt::Display for PrepareNote {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PrepareNote::NoUsableFace { object } => {
                write!(f, "object '{object}' has no usable face and is ignored")
            }
            PrepareNote::FlatUpToRounding { object, rounding } => write!(
                f,
                "object '{object}' is flat up to the rounding of its coordinates (rounding \
                 {rounding:.2e}): its faces tile one polygon, whose outline it takes as a light \
                 and as an occluder"
            ),
            PrepareNote::ConvexUpToRounding {
                object,
                outside,
                rounding,
                hull_faces,
                deviation,
            } => write!(
                f,
                "object '{object}' is convex up to the rounding of its coordinates (vertices at \
                 most {outside:.2e} outside its faces' planes, rounding {rounding:.2e}): its \
                 convex hull ({hull_faces} faces) stands in for it, within {deviation:.2e} of \
                 it; the solid angle it subtends from a point at distance d changes by at most \
                 about 2π·{deviation:.2e}/d"
            ),
            PrepareNote::NotConvex {
                object,
                closed_manifold,
                boundary_edges,
                nonmanifold_edges,
            } => {
                let how = if *closed_manifold {
                    "it takes its exact silhouette (read from a BSP tree, else computed at the \
                     point; face by face where that is degenerate)"
                } else if *nonmanifold_edges == 0 {
                    "as an occluder it takes the exact outline of its contour and boundary edges \
                     (read from a BSP tree, else computed at the point; face by face where that \
                     is degenerate), as a light it is handled face by face"
                } else {
                    "it is handled face by face"
                };
                write!(
                    f,
                    "object '{object}' is not convex (closed manifold: {closed_manifold}, \
                     boundary edges: {boundary_edges}, non-manifold edges: \
                     {nonmanifold_edges}): {how}"
                )
            }
            PrepareNote::NoTreesBuilt { objects } => {
                let (subject, its) = subject(objects);
                write!(
                    f,
                    "{subject}: no tree of precomputed silhouettes is built for this scene; \
                     {its} silhouette is computed at each point"
                )
            }
            PrepareNote::ConvexTreeOverBudget {
                objects,
                budget,
                limit,
            } => {
                let (subject, its) = subject(objects);
                write!(
                    f,
                    "{subject}: {its} face planes cut the scene into more than {} cells; {its} \
                     silhouette is computed at each point instead of read from a tree{}",
                    budget.map_or(*limit, |b| b.units),
                    budget_words(budget, *limit, "cells")
                )
            }
            PrepareNote::NoExactTree { objects, why } => {
                let (subject, its) = subject(objects);
                let why = match why {
                    NoExactTree::TooManyEdges { max_edges } => format!(
                        "mesh has more than {max_edges} edges, too many for a tree of \
                         precomputed silhouettes"
                    ),
                    NoExactTree::WindowCheaper => {
                        "silhouette inside each light's window costs less than reading the whole \
                         one from a tree of precomputed silhouettes (the cost model), so it gets \
                         no tree"
                            .to_string()
                    }
                    NoExactTree::OverBudget { budget, limit } => format!(
                        "tree of precomputed silhouettes would have more than {} leaves{}",
                        budget.map_or(*limit, |b| b.units),
                        budget_words(budget, *limit, "leaves")
                    ),
                };
                write!(
                    f,
                    "{subject}: {its} {why}; {its} exact silhouette is computed at each point"
                )
            }
            PrepareNote::SharedTree { objects } => write!(
                f,
                "objects {} are instances of one mesh and share one silhouette tree (built in \
                 the frame of '{}')",
                quoted(objects),
                objects.first().map_or("", String::as_str)
            ),
            PrepareNote::NotHoisted { objects, error } => write!(
                f,
                "{}: the tree stays leaf-stored: {error}",
                quoted(objects)
            ),
            PrepareNote::TreesDroppedByMove { object } => write!(
                f,
                "object '{object}' moved by a map that is not an affine image of its former \
                 vertices: its silhouette trees are dropped"
            ),
            PrepareNote::Path {
                object,
                faces,
                path,
            } => write!(f, "object '{object}' ({faces} faces): {}", path.describe()),
            PrepareNote::NotSeparated { light, occluder } => write!(
                f,
                "light '{light}' and occluder '{occluder}' are not separated by a plane: the \
                 light is taken face by face, each face cutting the occluder at its plane"
            ),
        }
    }
}

/// Everything preparing a scene found, in the order it found it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PrepareReport {
    pub notes: Vec<PrepareNote>,
}

impl PrepareReport {
    pub(crate) fn push(&mut self, note: PrepareNote) {
        self.notes.push(note);
    }

    /// Each note in its words, for a terminal or a list.
    pub fn lines(&self) -> Vec<String> {
        self.notes.iter().map(ToString::to_string).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A group of instances is named as a group, one object alone as one.
    #[test]
    fn subjects_follow_the_group() {
        let one = PrepareNote::NoTreesBuilt {
            objects: vec!["a".into()],
        };
        assert!(one.to_string().starts_with("object 'a': no tree"));
        assert!(one.to_string().contains("; its silhouette"));
        let two = PrepareNote::NoTreesBuilt {
            objects: vec!["a".into(), "b".into()],
        };
        assert!(two.to_string().starts_with("objects 'a', 'b': no tree"));
        assert!(two.to_string().contains("; their silhouette"));
    }

    /// The cost model's reasons are said only when it, not the hard limit, set the budget.
    #[test]
    fn budget_is_explained_only_below_the_limit() {
        let budget = TreeBudget {
            units: 500,
            saving_seconds: 0.25,
            queries: 1e6,
        };
        let note = |units| PrepareNote::ConvexTreeOverBudget {
            objects: vec!["c".into()],
            budget: Some(TreeBudget { units, ..budget }),
            limit: 1000,
        };
        let below = note(500).to_string();
        assert!(below.contains("more than 500 cells"), "{below}");
        assert!(below.contains("the cost model"), "{below}");
        let at = note(1000).to_string();
        assert!(!at.contains("the cost model"), "{at}");
    }
}
