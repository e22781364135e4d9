//! The command line as a user types it: negative numbers and vectors whose first coordinate is
//! negative are values, not flags; errors are one readable line, whatever RUST_BACKTRACE says;
//! `penumbra cache` shows and clears the cache it is pointed at.

#[cfg(feature = "gui")]
use clap::{Args, FromArgMatches};
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

    // The workbench's pick is a pair too (parsed by the library's own argument struct).
    #[cfg(feature = "gui")]
    {
        let cmd = penumbra::app::RunOptions::augment_args(clap::Command::new("gui"));
        let m = cmd
            .try_get_matches_from(["gui", "--pick", "-0.25,0.5"])
            .expect("a negative pick parses");
        let opts = penumbra::app::RunOptions::from_arg_matches(&m).unwrap();
        assert_eq!(opts.pick, Some((-0.25, 0.5)));
    }
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

/// `penumbra figure` (issue 28): the projected plane of a set difference, live and from the
/// debug dump `probe` wrote of the same pixel, is the same figure; as SVG it parses, with the
/// light's, the occluder's and the visible region as translucent fills; a set difference the
/// recording does not have, or an unknown view, is a one-line error.
#[test]
fn figure_of_a_set_difference_live_and_from_a_dump() {
    let dir = temp("figure");
    let dump = dir.join("p.json");
    let probe = [
        "probe", "default", "--size", "320x240", "--pixel", "150,170", "--json",
    ];
    let o = penumbra(&[&probe[..], &[dump.to_str().unwrap()]].concat(), &dir);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let live = dir.join("live.svg");
    let o = penumbra(
        &[
            "figure",
            "default",
            "--size",
            "320x240",
            "--pixel",
            "150,170",
            "--difference",
            "1",
            "--out",
            live.to_str().unwrap(),
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let replayed = dir.join("dump.svg");
    let o = penumbra(
        &[
            "figure",
            dump.to_str().unwrap(),
            "--difference",
            "1",
            "--out",
            replayed.to_str().unwrap(),
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (a, b) = (
        std::fs::read_to_string(&live).unwrap(),
        std::fs::read_to_string(&replayed).unwrap(),
    );
    assert_eq!(a, b, "the dump replays the live figure");
    usvg::Tree::from_str(&a, &usvg::Options::default()).expect("the SVG parses");
    // Three translucent regions and three legend swatches.
    assert_eq!(a.matches("fill-opacity").count(), 6, "{a}");
    let png = dir.join("dump.png");
    let o = penumbra(
        &[
            "figure",
            dump.to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
        ],
        &dir,
    );
    assert!(o.status.success() && png.is_file(), "{}", text(&o.stderr));
    for (args, want) in [
        (
            vec!["--difference", "99"],
            "set difference(s) at this point",
        ),
        (vec!["--view", "sphere"], "not available as a figure yet"),
    ] {
        let o = penumbra(
            &[&["figure", dump.to_str().unwrap()][..], &args[..]].concat(),
            &dir,
        );
        let err = text(&o.stderr);
        assert!(!o.status.success() && err.contains(want), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}
