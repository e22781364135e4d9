//! The command line as a user types it: negative numbers and vectors whose first coordinate is
//! negative are values, not flags; errors are one readable line, whatever RUST_BACKTRACE says;
//! `penumbra cache` shows and clears the cache it is pointed at.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn penumbra(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .env("PENUMBRA_CACHE_DIR", cache)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("the binary runs")
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(o: &[u8]) -> String {
    String::from_utf8_lossy(o).into_owned()
}

#[test]
fn negative_numbers_and_vectors_are_values_everywhere() {
    let dir = temp("negative");
    let out = dir.join("neg.png");
    let o = penumbra(
        &[
            "render",
            "default",
            "--eye",
            "-3,1.5,4",
            "--target",
            "-0.3,0.2,-0.3",
            "--up",
            "-0.1,1,0",
            "--fov",
            "40",
            "--size",
            "8x6",
            "--exposure",
            "-1.5",
            "--out",
            out.to_str().unwrap(),
        ],
        &dir.join("cache"),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    for ext in ["pfm", "exr", "png"] {
        assert!(out.with_extension(ext).exists(), "{ext} written");
    }

    // The same camera through `probe`, whose pixel is a pair.
    let json = dir.join("probe.json");
    let o = penumbra(
        &[
            "probe",
            "default",
            "--eye",
            "-3,1.5,4",
            "--target",
            "-0.3,0.2,-0.3",
            "--fov",
            "40",
            "--size",
            "8x6",
            "--pixel",
            "3,2",
            "--json",
            json.to_str().unwrap(),
        ],
        &dir.join("cache"),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(json.exists());

    // A negative value where none is valid is refused for what it is, not as a flag.
    let o = penumbra(
        &["stress", "--cases", "1", "--seed", "-1"],
        &dir.join("cache"),
    );
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(err.contains("invalid value '-1' for '--seed"), "{err}");
    assert!(!err.contains("unexpected argument"), "{err}");

    // A malformed vector names the token.
    let o = penumbra(
        &["render", "default", "--target", "-x,0,0"],
        &dir.join("cache"),
    );
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(err.contains("'-x'"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn errors_are_one_line_without_a_stack_trace() {
    let dir = temp("errors");
    let o = penumbra(&["render", "no-such-scene.toml"], &dir.join("cache"));
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(err.starts_with("error: no-such-scene.toml"), "{err}");
    assert!(!err.contains("Stack backtrace"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_cache_command_shows_trims_and_clears_only_its_files() {
    let dir = temp("cache");
    let cache = dir.join("trees");
    std::fs::create_dir_all(&cache).unwrap();
    // Two cache files and one file of the user's that must survive a clear.
    std::fs::write(cache.join("0123456789abcdef.json"), vec![b'x'; 3000]).unwrap();
    std::fs::write(cache.join("fedcba9876543210.json"), vec![b'x'; 2000]).unwrap();
    std::fs::write(cache.join("mine.txt"), "keep").unwrap();
    let json = dir.join("cache.json");
    let o = penumbra(&["cache", "--json", json.to_str().unwrap()], &cache);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let shown: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(shown["files"], 2);
    assert_eq!(shown["bytes"], 5000);
    assert!(text(&o.stdout).contains("2 files"));

    // A bound of 4000 bytes keeps the newer file only.
    let older = std::fs::File::options()
        .write(true)
        .open(cache.join("0123456789abcdef.json"))
        .unwrap();
    older
        .set_modified(std::time::SystemTime::now() - std::time::Duration::from_secs(3600))
        .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["cache", "--trim"])
        .env("PENUMBRA_CACHE_DIR", &cache)
        .env("PENUMBRA_CACHE_MAX", "4000")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!cache.join("0123456789abcdef.json").exists());
    assert!(cache.join("fedcba9876543210.json").exists());

    let o = penumbra(&["cache", "--clear"], &cache);
    assert!(o.status.success());
    assert!(text(&o.stdout).contains("deleted 1 files"));
    assert!(!cache.join("fedcba9876543210.json").exists());
    assert!(
        cache.join("mine.txt").exists(),
        "a file not of the cache stays"
    );

    // A bound that is not a size is an error naming the variable.
    let o = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .arg("cache")
        .env("PENUMBRA_CACHE_DIR", &cache)
        .env("PENUMBRA_CACHE_MAX", "lots")
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("PENUMBRA_CACHE_MAX"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `penumbra figure`: the projected plane of a set difference, live and from the
/// debug dump `probe` wrote of the same pixel, is the same figure; as SVG it parses, with the
/// light's, the occluder's and the visible region as translucent fills; a set difference the
/// recording does not have, or an unknown view, is a one-line error.
#[test]
fn figures_of_every_view_live_and_from_a_dump() {
    let dir = temp("figure");
    let dump = dir.join("p.json");
    let at = ["--size", "320x240", "--pixel", "130,170"];
    let probe = [
        &["probe", "default", "--gh-steps"][..],
        &at[..],
        &["--json"],
    ]
    .concat();
    let o = penumbra(&[&probe[..], &[dump.to_str().unwrap()]].concat(), &dir);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dump = dump.to_str().unwrap();
    // The stepper's stages of the first Greiner–Hormann difference at this point, from the
    // list that a stage out of range prints (the differences before it are classified or taken
    // as holes, which have no phases).
    let listing = text(&penumbra(&["figure", dump, "--stage", "999"], &dir).stderr);
    let stage_of = |phase: &str| {
        listing
            .lines()
            .find(|l| l.contains(phase))
            .and_then(|l| l.split_whitespace().next())
            .unwrap_or_else(|| panic!("no {phase} in {listing}"))
            .to_string()
    };
    let (phase1_stage, phase2_stage) = (stage_of("phase 1:"), stage_of("phase 2:"));
    // Each view, live and from the dump: the same SVG, which parses.
    for (k, (view, extra)) in [
        ("sphere", vec![]),
        ("hemisphere", vec!["--fit"]),
        ("plane", vec!["--difference", "1"]),
        ("plane", vec!["--stage", phase1_stage.as_str()]),
        ("plane", vec!["--stage", phase2_stage.as_str()]),
        ("light", vec![]),
        ("bsp", vec!["--orbit", "30,20,1.5"]),
    ]
    .into_iter()
    .enumerate()
    {
        let live = dir.join(format!("{k}_{view}_live.svg"));
        let replayed = dir.join(format!("{k}_{view}_dump.svg"));
        let args = [&["--view", view][..], &extra[..]].concat();
        let o = penumbra(
            &[
                &["figure", "default"][..],
                &at[..],
                &args[..],
                &["--out", live.to_str().unwrap()],
            ]
            .concat(),
            &dir,
        );
        assert!(o.status.success(), "{view}: {}", text(&o.stderr));
        let o = penumbra(
            &[
                &["figure", dump][..],
                &args[..],
                &["--out", replayed.to_str().unwrap()],
            ]
            .concat(),
            &dir,
        );
        assert!(o.status.success(), "{view}: {}", text(&o.stderr));
        let (a, b) = (
            std::fs::read_to_string(&live).unwrap(),
            std::fs::read_to_string(&replayed).unwrap(),
        );
        assert_eq!(a, b, "{view} {extra:?}: the dump replays the live figure");
        usvg::Tree::from_str(&a, &usvg::Options::default()).expect("the SVG parses");
        // The same figure as PDF and PNG.
        for ext in ["pdf", "png"] {
            let f = dir.join(format!("{k}_{view}.{ext}"));
            let o = penumbra(
                &[
                    &["figure", dump][..],
                    &args[..],
                    &["--out", f.to_str().unwrap()],
                ]
                .concat(),
                &dir,
            );
            let len = std::fs::metadata(&f).map_or(0, |m| m.len());
            assert!(
                o.status.success() && len > 1000,
                "{view} {ext}: {}",
                text(&o.stderr)
            );
        }
    }
    // GH phases 1 (intersections, circled) and 2 (entry and exit labels).
    let phase1 = std::fs::read_to_string(dir.join("3_plane_live.svg")).unwrap();
    let phase2 = std::fs::read_to_string(dir.join("4_plane_live.svg")).unwrap();
    assert!(
        phase1.contains("GH phase 1") && phase1.contains("<circle"),
        "{phase1}"
    );
    assert!(
        phase2.contains("GH phase 2") && phase2.contains(", entry"),
        "{phase2}"
    );
    for (args, want) in [
        (
            vec!["--view", "plane", "--difference", "99"],
            "no set difference 99",
        ),
        (vec!["--view", "cube"], "view cube: expected"),
        (vec!["--view", "environment"], "no environment light"),
        (vec!["--out", "x.gif"], "written as .svg, .pdf or .png"),
        (vec!["--orbit", "1"], "YAW,PITCH"),
    ] {
        let args = [&["figure", dump][..], &args[..]].concat();
        let o = penumbra(&args, &dir);
        let err = text(&o.stderr);
        assert!(!o.status.success() && err.contains(want), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    // A stage out of range lists the stepper's stages.
    let o = penumbra(&["figure", dump, "--stage", "999"], &dir);
    let err = text(&o.stderr);
    assert!(!o.status.success() && err.contains("    1  light"), "{err}");
    // The environment's view on env_figures, live and from a dump.
    let env_dump = dir.join("env.json");
    let at = ["--size", "64x48", "--pixel", "27,41"];
    let o = penumbra(
        &[
            &["probe", "env_figures", "--gh-steps"][..],
            &at[..],
            &["--json", env_dump.to_str().unwrap()],
        ]
        .concat(),
        &dir,
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (live, replayed) = (dir.join("env_live.svg"), dir.join("env_dump.svg"));
    let o = penumbra(
        &[
            &["figure", "env_figures", "--view", "environment"][..],
            &at[..],
            &["--out", live.to_str().unwrap()],
        ]
        .concat(),
        &dir,
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = penumbra(
        &[
            "figure",
            env_dump.to_str().unwrap(),
            "--view",
            "environment",
            "--out",
            replayed.to_str().unwrap(),
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let a = std::fs::read_to_string(&live).unwrap();
    assert_eq!(a, std::fs::read_to_string(&replayed).unwrap());
    assert!(a.contains("dynamic term"), "the union terms are drawn");
}
