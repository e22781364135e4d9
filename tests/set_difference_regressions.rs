//! Set-difference configurations found by comparing renders with the ray-cast reference or by
//! the realistic chains of `set_difference_chains.rs`, each checked against the
//! convex-decomposition second algorithm (the clip polygons are convex).

use glam::DVec3;
use penumbra::geometry::{PlanarPolygon, SetDifference, SphericalPolygon, orient};

/// Area of subject − clip for a convex clip by decomposition: the parts of the subject outside
/// each clip edge in turn (Sutherland–Hodgman on the sphere), summed.
fn decomposition_area(subject: &[DVec3], clip: &[DVec3]) -> f64 {
    fn clip_half(poly: &[DVec3], a: DVec3, b: DVec3, keep_left: bool) -> Vec<DVec3> {
        let mut out = Vec::new();
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (dp, dq) = (orient(a, b, p), orient(a, b, q));
            let (ip, iq) = ((dp >= 0.0) == keep_left, (dq >= 0.0) == keep_left);
            if ip {
                out.push(p);
            }
            if ip != iq {
                out.push((p * dq.abs() + q * dp.abs()).normalize());
            }
        }
        out
    }
    let mut total = 0.0;
    let mut rest = subject.to_vec();
    for i in 0..clip.len() {
        let (a, b) = (clip[i], clip[(i + 1) % clip.len()]);
        let outside = clip_half(&rest, a, b, false);
        if outside.len() >= 3 {
            let mut s = SphericalPolygon::new();
            s.push_loop(outside);
            total += s.signed_solid_angle_about(DVec3::Z);
        }
        rest = clip_half(&rest, a, b, true);
        if rest.len() < 3 {
            break;
        }
    }
    total
}

fn check(subject: &[DVec3], clip: &[DVec3]) {
    check_loops(&[subject], clip);
}

/// `subject − clip` for a subject of several loops (outer loops and holes) against the sum of
/// the decompositions of its loops (signed areas add up for holes too).
fn check_loops(subject: &[&[DVec3]], clip: &[DVec3]) {
    let got = difference_area(subject, clip);
    let want: f64 = subject.iter().map(|lp| decomposition_area(lp, clip)).sum();
    assert!(
        (got - want).abs() < 1e-12,
        "set difference {got} vs decomposition {want}"
    );
}

/// The solid angle of `subject − clip` by the set difference (whose traversal must be
/// consistent), the subject given as loops.
fn difference_area(subject: &[&[DVec3]], clip: &[DVec3]) -> f64 {
    let mut s = PlanarPolygon::new();
    for lp in subject {
        s.push_loop(lp.iter().copied());
    }
    let mut c = PlanarPolygon::new();
    c.push_loop(clip.iter().copied());
    let mut out = PlanarPolygon::new();
    let mut sd = SetDifference::new();
    sd.subtract(&s, &c, &mut out, None);
    assert!(sd.last_traversal_consistent());
    let mut res = SphericalPolygon(out.0.clone());
    res.map_vertices(|v| v.normalize());
    res.signed_solid_angle_about(DVec3::Z)
}

#[test]
fn chair_back_behind_seat_gap() {
    // Floor point under the chair of the `chair` scene: the light minus the seat and a leg,
    // minus the back, whose silhouettes share near-coincident corners (1 mm gaps in the chair).
    let subject = [
        DVec3::new(0.41977752651736, -0.2531707225940665, 0.8716027842154734),
        DVec3::new(0.26929381453359974, -0.4857252616585369, 0.8315959425350086),
        DVec3::new(0.44426334566414116, -0.5337894065257232, 0.7195129944484813),
        DVec3::new(0.47422318739245, -0.494658704177364, 0.7283029142608974),
        DVec3::new(0.4607367810463449, -0.49104057570648935, 0.7393245373994373),
        DVec3::new(0.43191949838633925, -0.4603279092778839, 0.7755925237220544),
        DVec3::new(0.5274874401999744, -0.3085187989997241, 0.7915637378600958),
    ];
    let clip = [
        DVec3::new(0.4313671662985189, -0.4597392489461246, 0.7762487944068187),
        DVec3::new(0.4702782851928682, -0.4717273068563098, 0.7458630453656679),
        DVec3::new(0.7291696415518781, 0.15202026312018163, 0.6672341968454378),
        DVec3::new(0.7011301229793777, 0.1846031495616251, 0.6887221702710395),
        DVec3::new(0.4397866383195552, 0.11579305453874657, 0.8906063559598997),
        DVec3::new(0.2507960248441329, -0.26729149807550184, 0.9304066900979029),
    ];
    check(&subject, &clip);
}

#[test]
fn loop_containment_along_the_meridian_of_a_vertical_edge() {
    // Chain 3672 of `set_difference_chains.rs` (before the fix): a floor point, the light split
    // into two loops by a first box; the second box rests on the floor, and its vertical edge
    // projects to the meridian through the top vertex of the small loop (the boxes are aligned).
    // The small loop has no intersection with the box and is classified by the winding number
    // of that vertex along its meridian, which ran along the box's edge: the side of the vertex
    // relative to the edge's line was rounding noise, and the loop was dropped.
    let small = [
        DVec3::new(0.3503203679591666, 0.9099202940319966, 0.22208263845172346),
        DVec3::new(0.49516103035418535, 0.8288979562452196, 0.260276261213119),
        DVec3::new(0.5037153205976459, 0.8432178103235201, 0.18776208389453714),
    ];
    let large = [
        DVec3::new(0.7889056982755612, 0.5238684702812324, 0.321231419810626),
        DVec3::new(0.8541098508729754, 0.4709953038668438, 0.2205896334307737),
        DVec3::new(0.6317489603493845, 0.7504846983021113, 0.19407722357829887),
        DVec3::new(0.6165284023549055, 0.7324034720692119, 0.2889253938141656),
    ];
    let clip = [
        DVec3::new(0.5081465358326949, 0.8506356502318575, 0.1349299398793943),
        DVec3::new(0.6061572454384228, 0.7816148721076684, 0.14714477735419912),
        DVec3::new(0.6378327170313011, 0.7577118828081953, 0.13799321626706212),
        DVec3::new(0.6439936925995056, 0.7650307993094485, 0.0),
        DVec3::new(0.5128363517321434, 0.8584863868123161, 0.0),
    ];
    check_loops(&[&small, &large], &clip);
}

#[test]
fn nearly_parallel_edges_ending_at_the_line_tolerance() {
    // Case 8 039 682 of the near-degeneracy stress run (δ = 7.9e-11): a light edge and an
    // occluder edge 0.4 rad long at an angle of 2e-10 cross 5e-3 rad from their ends, each
    // end lying 1.000e-12 from the other edge's line, i.e. at the line tolerance. Deciding the
    // crossing with tolerance-classified signs called one end "on the line" (outside the other
    // edge: no T contact) and the other "off" (no T contact either) and lost the crossing.
    let subject = [
        DVec3::new(0.4739311332485434, 0.4688413567456092, 0.7453704200883529),
        DVec3::new(0.2959322628764743, 0.8704223997736912, 0.3934322581601792),
        DVec3::new(-0.6553255268132027, 0.7361524498921158, 0.16919818091467329),
        DVec3::new(-0.676621775128205, 0.2931610786733259, 0.6754550728016253),
    ];
    let clip = [
        DVec3::new(-0.6766217751439471, 0.29316107873733976, 0.6754550727580727),
        DVec3::new(0.4739311332898512, 0.46884135667995736, 0.7453704201033835),
        DVec3::new(0.5148875462112034, 0.8526202123424523, 0.08904823559014316),
        DVec3::new(0.4953708909689122, 0.8686815759417637, 0.0),
        DVec3::new(0.28573870545749797, 0.9583075666003442, 0.0),
        DVec3::new(
            -0.08056537218783918,
            0.9960898649342351,
            0.036251921046096196,
        ),
        DVec3::new(-0.6553255268668329, 0.7361524498545333, 0.1691981808704719),
    ];
    check(&subject, &clip);
}

#[test]
fn sliver_loop_touching_a_thin_occluder_face() {
    // `polyhedra` scene, pixel (72, 142) at 480×360: the light `hole` shaded face by face, its
    // face 18 minus earlier faces of itself left a 7-vertex loop and a 3-vertex sliver (edges
    // of 1e-5 rad); its face 8, nearly edge-on, is the clip. It made phase 2 follow a missing
    // successor link (an index out of bounds: a panic in the renderer).
    let outer = [
        DVec3::new(0.9064229452922438, 0.08579667788207847, 0.4135654413900332),
        DVec3::new(0.8992500696425583, 0.019240724118670376, 0.4370115636722252),
        DVec3::new(
            0.9086181069513091,
            0.0014116404509723548,
            0.4176256014559651,
        ),
        DVec3::new(
            0.9086181069794543,
            0.0014116406433427424,
            0.4176256013940799,
        ),
        DVec3::new(
            0.9086181069788919,
            0.0014116406426228267,
            0.41762560139530597,
        ),
        DVec3::new(0.91387390903951, 0.044502049308761886, 0.4035517884784626),
        DVec3::new(0.9185654020625471, 0.11627274978679449, 0.37778069007122156),
    ];
    let sliver = [
        DVec3::new(0.9186634379394653, 0.11654189736789755, 0.37745923482030863),
        DVec3::new(0.9186090304054716, 0.11639247192306561, 0.3776377122814373),
        DVec3::new(0.9186589504184918, 0.1163806156722092, 0.3775199135300712),
    ];
    let clip = [
        DVec3::new(0.9186634379390526, 0.11654189736728582, 0.37745923482150134),
        DVec3::new(0.9185690304295301, 0.11640196813140032, 0.3777320719119436),
        DVec3::new(0.9374872110374862, 0.11146162095600523, 0.3296877859354445),
    ];
    check_loops(&[&outer, &sliver], &clip);
}

/// A subject loop that passes twice through one point (two squares touching at a corner,
/// written as one loop, as a traversal that met two loops touching there can write it) gives
/// the same difference as the two loops written apart, and as the decomposition oracle.
#[test]
fn a_loop_through_one_point_twice_is_two_loops() {
    let p = |x: f64, y: f64| DVec3::new(0.05 * x, 0.05 * y, 1.0).normalize();
    let pinched = [
        p(0.0, 0.0),
        p(1.0, 0.0),
        p(1.0, 1.0),
        p(2.0, 1.0),
        p(2.0, 2.0),
        p(1.0, 2.0),
        p(1.0, 1.0),
        p(0.0, 1.0),
    ];
    let first = [p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)];
    let second = [p(1.0, 1.0), p(2.0, 1.0), p(2.0, 2.0), p(1.0, 2.0)];
    // Clips through the shared corner, over one square's edge, and around the corner.
    let clips: [Vec<DVec3>; 3] = [
        vec![p(0.5, 0.5), p(1.5, 0.6), p(1.4, 1.5)],
        vec![p(1.0, 1.0), p(1.8, 1.2), p(1.5, 1.9)],
        vec![p(0.7, 0.7), p(1.3, 0.7), p(1.3, 1.3), p(0.7, 1.3)],
    ];
    for clip in &clips {
        let got = difference_area(&[&pinched], clip);
        let want = decomposition_area(&first, clip) + decomposition_area(&second, clip);
        assert!(
            (got - want).abs() < 1e-12,
            "set difference {got} vs decomposition {want}"
        );
    }
}

/// `suzanne.obj` (tests/data/blender), pixel (73, 48) at 128×128: a light nearly edge-on from
/// a point on the monkey, minus the image of a neighbouring face nearly in the tangent plane:
/// a sliver 5e-15 rad high along the horizon, whose short edges the loading folds. What was
/// left of it, a triangle with every vertex on the horizon, deleted the light, and the
/// degenerate remainder integrated to 10⁵ times the unshadowed value.
#[test]
fn a_sliver_along_the_horizon_removes_nothing() {
    let light = [
        DVec3::new(0.8487228119159616, -0.5288379605639741, 0.0),
        DVec3::new(0.8375575504818447, -0.5461606751762993, 0.01434804940823177),
        DVec3::new(0.8389134715105578, -0.5442648135954632, 0.0),
    ];
    let sliver = [
        DVec3::new(0.9722194793717032, 0.23407110870462958, 0.0),
        DVec3::new(
            0.9722194793716924,
            0.2340711087046748,
            5.566480440930488e-15,
        ),
        DVec3::new(
            -0.412460195333558,
            -0.9109756238590598,
            4.057076674999328e-15,
        ),
        DVec3::new(-0.4124601953335439, -0.9109756238590662, 0.0),
        DVec3::new(0.6372720133156854, -0.7706389433739855, 0.0),
    ];
    let mut s = PlanarPolygon::new();
    s.push_loop(light.iter().copied());
    let mut c = PlanarPolygon::new();
    c.push_loop(sliver.iter().copied());
    let mut out = PlanarPolygon::new();
    let mut sd = SetDifference::new();
    sd.subtract(&s, &c, &mut out, None);
    let area = |p: &PlanarPolygon| {
        let mut q = SphericalPolygon(p.0.clone());
        q.map_vertices(|v| v.normalize());
        q.signed_solid_angle_about(DVec3::Z)
    };
    // The sliver's own area (2e-14 sr) bounds what may go.
    let (before, after) = (area(&s), area(&out));
    assert!(
        (before - after).abs() <= 2e-14,
        "{before} before, {after} after"
    );
}

/// A walk that crosses its bound (forced by capping every walk at a few steps) ends the
/// difference at once, empty, inconsistent and flagged; the same workspace then computes the
/// next difference as if nothing happened. Oracle: the decomposition.
#[test]
fn a_walk_over_its_bound_ends_the_difference_and_says_so() {
    let square = |c: DVec3, r: f64| -> Vec<DVec3> {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| (c + DVec3::new(x * r, y * r, 0.0)).normalize())
            .collect()
    };
    let subject = square(DVec3::Z, 0.3);
    let clip = square(DVec3::new(0.2, 0.1, 1.0), 0.2);
    let (mut s, mut c, mut out) = (
        PlanarPolygon::new(),
        PlanarPolygon::new(),
        PlanarPolygon::new(),
    );
    s.push_loop(subject.iter().copied());
    c.push_loop(clip.iter().copied());
    let mut sd = SetDifference::new();
    for steps in 0..4 {
        sd.limit_walks(Some((steps, 0)));
        sd.subtract(&s, &c, &mut out, None);
        assert!(sd.last_bound_crossed(), "capped at {steps} steps");
        assert!(out.is_empty() && !sd.last_traversal_consistent());
    }
    sd.limit_walks(None);
    sd.subtract(&s, &c, &mut out, None);
    assert!(!sd.last_bound_crossed() && sd.last_traversal_consistent());
    let mut res = SphericalPolygon(out.0.clone());
    res.map_vertices(|v| v.normalize());
    let got = res.signed_solid_angle_about(DVec3::Z);
    let want = decomposition_area(&subject, &clip);
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
}

/// Found by `penumbra stress --family real-meshes` (seed 2, case 65101): a point on Blender's
/// torus (vertices perturbed by 1e-5 of its radius), face by face. The visible polygon so far
/// reaches the horizon at a point that the next face's sliver (a neighbouring face seen at a
/// grazing angle, clipped to the horizon) starts from too, and the sliver ends 1e-11 from it
/// along the horizon. The difference came out empty: the point was black where rays see 4 %
/// of the light.
#[test]
fn a_grazing_sliver_from_a_shared_horizon_point() {
    let subject = [
        DVec3::new(
            0.8865266465636736,
            -0.32649370514913645,
            0.32782978118309486,
        ),
        DVec3::new(-0.246066955665919, -0.8906094865285952, 0.38244711508204426),
        DVec3::new(
            -0.29332143171433617,
            -0.9558542445307067,
            0.017470000277159916,
        ),
        DVec3::new(-0.10898140670277813, -0.9940437882674403, 0.0),
        DVec3::new(0.7724854190656102, -0.6350325010037112, 0.0),
        DVec3::new(0.9443723601735132, -0.328878161721618, 9.105909864080929e-6),
    ];
    let clip = [
        DVec3::new(0.7724854190656102, -0.6350325010037112, 0.0),
        DVec3::new(0.6526303069001276, 0.7576765020916276, 2.633706848597321e-5),
        DVec3::new(0.9553916444270911, -0.2916223564832243, 0.0467248002464393),
        DVec3::new(0.7724854190604374, -0.6350325010100039, 0.0),
    ];
    check(&subject, &clip);
}

/// `subject − clip` lies inside the subject: every output vertex within 1e-12 rad of it, and
/// its area that of the convex decomposition up to the rounding of the solid angles (fans
/// about +z, whose terms round to some 1e-17 sr each however small the polygon is: both
/// subjects below are smaller than what this check can resolve, so the vertices decide).
fn check_inside(subject: &[DVec3], clip: &[DVec3]) {
    let mut s = PlanarPolygon::new();
    s.push_loop(subject.iter().copied());
    let mut c = PlanarPolygon::new();
    c.push_loop(clip.iter().copied());
    let mut out = PlanarPolygon::new();
    let mut sd = SetDifference::new();
    sd.subtract(&s, &c, &mut out, None);
    assert!(sd.last_traversal_consistent());
    let mut whole = SphericalPolygon::new();
    whole.push_loop(subject.iter().map(|v| v.normalize()));
    for v in out.0.vertices() {
        assert!(whole.contains_within(v.normalize(), 1e-12), "{v:?} outside");
    }
    let got = difference_area(&[subject], clip);
    let want = decomposition_area(subject, clip);
    assert!(
        (got - want).abs() <= 1e-15,
        "set difference {got} vs decomposition {want}"
    );
}

/// Stress case 846323 (a text lit by itself, face by face): a light face 4e-7 rad wide on the
/// horizon, minus an occluder face seen 1e-5 rad above it whose corner, 5e-7 rad from the
/// light face, is 1e-6 rad wide. The light's vertices lay within the line tolerance of both
/// of the corner's edges; the corner rule took them for the corner and the traversal put the
/// occluder's far corners, 80° away, into the result. The corner's tip, thinner than the
/// tolerances, is cut off on loading.
#[test]
fn a_light_vertex_near_a_hair_thin_corner_is_not_the_corner() {
    let subject = [
        DVec3::new(
            0.5445641539707019,
            -0.8387191915097714,
            1.8354852058447814e-6,
        ),
        DVec3::new(
            0.5445641539511327,
            -0.8387191915244858,
            1.4446231807165958e-11,
        ),
        DVec3::new(
            0.5445645682120737,
            -0.8387189225527215,
            7.888566579000154e-12,
        ),
    ];
    let clip = [
        DVec3::new(
            -0.36604013038222327,
            -0.9305990666337264,
            1.1410622198344656e-5,
        ),
        DVec3::new(
            -0.42915100522784244,
            -0.9032327577009338,
            1.1309214160608436e-5,
        ),
        DVec3::new(
            0.5445650665477768,
            -0.8387185989924246,
            1.2421574646501902e-17,
        ),
    ];
    check_inside(&subject, &clip);
}

/// Stress case 319850 (a text lit by itself, face by face): the tip of a light face, 3.5e-8
/// rad long, minus an occluder face 7e-9 rad long and 4e-13 rad wide along the tip's base.
/// The sliver test took the occluder's great circle from a × b of two of its corners, whose
/// rounding (1e-16 / 7e-9) is far above its width: the sliver was kept, and its corners
/// entered the result 3e-9 rad outside the light.
#[test]
fn a_sliver_shorter_than_its_rounding_is_still_a_sliver() {
    let subject = [
        DVec3::new(0.8994896284867003, -0.41121409574416884, 0.1477206001414944),
        DVec3::new(0.8994896137860672, -0.4112141276564743, 0.14772060082032176),
        DVec3::new(0.8994896140357411, -0.4112141277706203, 0.14772059898227247),
    ];
    let clip = [
        DVec3::new(0.8994896133763105, -0.4112141274691416, 0.14772060383686442),
        DVec3::new(0.8994896143222466, -0.411214127901605, 0.14772059687307823),
        DVec3::new(
            0.8994896134187227,
            -0.41121412748813907,
            0.14772060352572774,
        ),
    ];
    check_inside(&subject, &clip);
}
