//! Trees lent by a `TreeLibrary` (what every stress case reads) give the same shading as the
//! scene's own trees and as silhouettes computed at the point, for meshes that are the
//! library's turned, scaled (non-uniformly for boxes and cylinders) and moved; and the points
//! looked up do fall inside the library's trees.

use penumbra::scene::Material;
use penumbra::shading::{Method, NoRecorder, PrepareOptions, PreparedScene, ShadingScratch, shade};
use penumbra::stress::{CaseKind, generate, tree_library};

#[test]
fn borrowed_trees_shade_like_own_trees_and_like_the_silhouette_at_the_point() {
    let library = tree_library();
    let material = Material {
        kd: glam::DVec3::ONE,
        ks: glam::DVec3::splat(0.5),
        alpha: 0.3,
        ..Material::default()
    };
    let mut scratch = ShadingScratch::default();
    let (mut borrowed_objects, mut inside, mut cases, mut worst) = (0, 0, 0, 0.0f64);
    // 4,500 cases hold about 870 of these two kinds (10 of every 51).
    for index in 0..4500 {
        let case = generate(3, index);
        if !matches!(case.kind, CaseKind::NonConvex | CaseKind::Random) {
            continue;
        }
        cases += 1;
        let lent = PreparedScene::prepare(
            &case.scene,
            PrepareOptions {
                library: Some(library),
                ..PrepareOptions::default()
            },
        );
        assert_eq!(lent.trees_built, 0, "case {index}: every tree is borrowed");
        for o in lent.objects.iter().filter(|o| library.lends_to(o)) {
            borrowed_objects += 1;
            let (lo, hi) = match (o.convex_tree(), o.exact_tree()) {
                (Some(t), _) => (t.lo, t.hi),
                (_, Some(t)) => (t.lo, t.hi),
                _ => unreachable!("a lent object has a tree"),
            };
            let x = o.tree_point(case.point.position);
            inside += (x.cmpge(lo).all() && x.cmple(hi).all()) as usize;
        }
        let mut on_the_fly = lent.clone();
        on_the_fly.drop_silhouette_trees();
        // The scene's own trees cost up to seconds a case: a few cases only.
        let own = (cases <= 12).then(|| {
            PreparedScene::prepare(
                &case.scene,
                PrepareOptions {
                    ..PrepareOptions::default()
                },
            )
        });
        let mut value = |p: &PreparedScene| {
            shade(
                p,
                &case.point,
                &material,
                Method::Analytic,
                &mut scratch,
                &mut NoRecorder,
            )
        };
        let (a, c) = (value(&lent), value(&on_the_fly));
        let b = own.as_ref().map_or(c, &mut value);
        let scale = c.abs().max_element().max(1e-300);
        let err = (a - c).abs().max_element().max((b - c).abs().max_element()) / scale;
        worst = worst.max(err);
        assert!(
            err <= 1e-9,
            "case {index} ({:?}): lent {a}, own {b}, at the point {c}",
            case.kind
        );
    }
    assert!(cases > 800, "{cases} cases");
    assert!(borrowed_objects > cases, "{borrowed_objects} objects");
    // Most lookups are answered by the lent trees (the rest take the silhouette at the point).
    assert!(
        2 * inside > borrowed_objects,
        "{inside} of {borrowed_objects} inside"
    );
    eprintln!(
        "{cases} cases, {borrowed_objects} objects on lent trees ({inside} looked up inside \
         their box), worst relative difference {worst:e}"
    );
}
