"""penumbra from Python against the command line: the same images bit for bit,
the same comparison metrics, errors as exceptions, and two scenes rendering at once.

The command line is ``PENUMBRA_CLI`` or ``target/release/penumbra`` of this repository.
"""

import json
import os
import pathlib
import subprocess
import threading

import numpy as np
import pytest

import penumbra

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = os.environ.get("PENUMBRA_CLI", str(ROOT / "target" / "release" / "penumbra"))

METHODS = [
    "analytic",
    "per-triangle",
    "unshadowed",
    "mc",
    "control-variate",
    "ratio",
    "ratio-gray",
    "ratio-denoised",
    "ratio-bilateral",
    "reference",
    "analytic-exact",
]


def read_pfm(path):
    """A PFM (colour, little-endian) as an (h, w, 3) float32 array, top row first."""
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        assert scale < 0, "little-endian"
        data = np.frombuffer(f.read(), dtype="<f4", count=w * h * 3)
    return data.reshape(h, w, 3)[::-1]


def cli(*args, cwd):
    return subprocess.run([CLI, *args], cwd=cwd, capture_output=True, text=True, check=True)


@pytest.mark.parametrize("method", METHODS)
def test_render_equals_the_cli_bit_for_bit(method, tmp_path):
    scene = penumbra.load_scene("default")
    ours = scene.render(method=method, size=(32, 24), spp=4, seed=3)
    assert ours.dtype == np.float32 and ours.shape == (24, 32, 3)
    cli(
        "render", "default", "--size", "32x24", "--method", method, "--spp", "4",
        "--seed", "3", "--out", str(tmp_path / "x.png"), cwd=tmp_path,
    )
    theirs = read_pfm(tmp_path / "x.pfm")
    assert np.array_equal(ours.view(np.uint32), theirs.view(np.uint32)), method


def test_an_environment_render_equals_the_cli(tmp_path):
    scene = penumbra.load_scene("env_figures")
    ours = scene.render(size=(32, 24))
    cli("render", "env_figures", "--size", "32x24", "--out", str(tmp_path / "e.png"), cwd=tmp_path)
    assert np.array_equal(ours, read_pfm(tmp_path / "e.pfm"))


def test_compare_gives_the_cli_metrics(tmp_path):
    scene = penumbra.load_scene("default")
    image = scene.render(method="mc", size=(32, 24), spp=2)
    reference = scene.render(size=(32, 24))
    ours = penumbra.compare(image, reference)
    for name, img in [("a", image), ("b", reference)]:
        h, w, _ = img.shape
        with open(tmp_path / f"{name}.pfm", "wb") as f:
            f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
            f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())
    out = cli("compare", "a.pfm", "b.pfm", cwd=tmp_path).stdout
    assert ours == json.loads(out)
    assert ours["rmse"] > 0
    assert penumbra.compare(reference, reference)["rmse"] == 0


def test_errors_are_exceptions_with_the_message(tmp_path):
    with pytest.raises(FileNotFoundError, match="no_such_scene.obj"):
        penumbra.load_scene(str(tmp_path / "no_such_scene.obj"))
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(ValueError, match=r"bad\.obj"):
        penumbra.load_scene(str(bad))
    scene = penumbra.load_scene("default")
    with pytest.raises(ValueError, match="method"):
        scene.render(method="magic")
    with pytest.raises(ValueError, match="positive"):
        scene.render(size=(0, 10))
    with pytest.raises(ValueError, match="camera"):
        scene.camera = penumbra.Camera((0, 0, 0), (0, 0, 0))


def test_two_scenes_render_at_once_as_they_do_alone():
    names = ["default", "fig4"]
    alone = {n: penumbra.load_scene(n).render(size=(48, 36)) for n in names}
    together = {}

    def run(name):
        together[name] = penumbra.load_scene(name).render(size=(48, 36))

    threads = [threading.Thread(target=run, args=(n,)) for n in names]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for n in names:
        assert np.array_equal(alone[n], together[n]), n


def test_scenes_objects_and_camera():
    assert "default" in penumbra.scenes()
    scene = penumbra.load_scene("default")
    assert "seat" in scene.objects
    cam = scene.camera
    assert cam is not None and cam.fov_deg > 0
    moved = penumbra.Camera(cam.eye, cam.target, cam.up, cam.fov_deg * 0.5)
    scene.camera = moved
    assert scene.camera.fov_deg == pytest.approx(cam.fov_deg * 0.5)


def test_probe_equals_the_dump_and_its_figures_the_cli_s(tmp_path):
    scene = penumbra.load_scene("default")
    rec = scene.probe(150, 170, size=(320, 240))
    cli(
        "probe", "default", "--size", "320x240", "--pixel", "150,170", "--gh-steps",
        "--json", str(tmp_path / "p.json"), cwd=tmp_path,
    )
    dump = (tmp_path / "p.json").read_text()
    assert json.loads(rec.to_json()) == json.loads(dump)
    assert len(rec.stages) > 10 and rec.stages[0].startswith("light panel_light: silhouette")
    light = rec.stages[0].split(":")[0].split()[1]
    for view, stage, name in [("sphere", None, None), ("hemisphere", 1, None), ("plane", 8, None),
                              ("light", 1, None), ("bsp", None, light)]:
        fig = rec.figure(view=view, stage=stage, light=name)
        args = ["figure", str(tmp_path / "p.json"), "--view", view, "--out", f"{view}.svg"]
        if stage:
            args += ["--stage", str(stage)]
        if name:
            args += ["--light", name]
        cli(*args, cwd=tmp_path)
        assert fig.svg() == (tmp_path / f"{view}.svg").read_text(), view
        assert fig._repr_svg_().startswith("<svg")
    fig = rec.figure()
    for ext in ["svg", "pdf", "png"]:
        fig.save(str(tmp_path / f"f.{ext}"))
        assert (tmp_path / f"f.{ext}").stat().st_size > 1000
    with pytest.raises(ValueError, match="stage 999"):
        rec.figure(stage=999)
    with pytest.raises(ValueError, match="view cube"):
        rec.figure(view="cube")
    with pytest.raises(ValueError, match="light nothing: the lights are"):
        rec.figure(view="light", light="nothing")


def test_move_is_penumbra_edit(tmp_path):
    scene = penumbra.load_scene("default")
    before = scene.render(size=(32, 24))
    scene.move("seat", translate=(0.2, 0.0, -0.1), rotate_y=15.0)
    ours = scene.render(size=(32, 24))
    cli(
        "edit", "default", "--move", "seat", "--translate", "0.2,0,-0.1", "--rotate-y", "15",
        "--out", str(tmp_path / "moved.toml"), cwd=tmp_path,
    )
    cli("render", str(tmp_path / "moved.toml"), "--size", "32x24", "--out", "m.png", cwd=tmp_path)
    theirs = read_pfm(tmp_path / "m.pfm")
    assert not np.array_equal(before, ours), "the seat's shadow moved"
    assert np.array_equal(ours, theirs)
    with pytest.raises(ValueError, match="no object is named"):
        scene.move("nothing", translate=(1, 0, 0))


def test_calls_on_an_unchanged_scene_share_one_preparation():
    scene = penumbra.load_scene("default")
    first = scene.render(size=(32, 24))
    shared = scene.render(method="per-triangle", size=(32, 24))
    scene.probe(16, 12, size=(32, 24))
    assert scene.preparations == 1
    # What a kept preparation renders is what a fresh one does, bit for bit.
    fresh = penumbra.load_scene("default").render(method="per-triangle", size=(32, 24))
    assert np.array_equal(shared.view(np.uint32), fresh.view(np.uint32))
    assert np.array_equal(first, scene.render(size=(32, 24)))
    assert scene.preparations == 1
    # Another image size sizes the trees anew; a move changes the scene.
    scene.render(size=(48, 36))
    assert scene.preparations == 2
    scene.move("seat", translate=(0.1, 0.0, 0.0))
    scene.render(size=(48, 36))
    assert scene.preparations == 3


# Each call is minutes of work uninterrupted.
LONG_CALLS = {
    "render": lambda: penumbra.load_scene("default").render(
        method="reference", size=(320, 240), spp=4096
    ),
    "bench": lambda: penumbra.bench(penumbra.load_scene("default"), size=(320, 240)),
    "stress": lambda: penumbra.stress(cases=10_000_000, rays=256),
}


@pytest.mark.parametrize("call", sorted(LONG_CALLS))
def test_ctrl_c_cancels_within_a_second(call):
    import signal
    import time

    if call == "stress":
        # Its trees of the thesis' polyhedra are built once per process (about 3 s, not
        # interruptible); Ctrl-C is promised within a case after that.
        penumbra.stress(cases=1)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        LONG_CALLS[call]()
    elapsed = time.perf_counter() - start
    assert elapsed < 1.5, f"{call} stopped {elapsed - 0.5:.2f} s after Ctrl-C"


def test_stress_gives_the_cli_report(tmp_path):
    ours = penumbra.stress(cases=40, seed=7, rays=64)
    cli("stress", "--cases", "40", "--seed", "7", "--rays", "64", "--json", "s.json", cwd=tmp_path)
    theirs = json.loads((tmp_path / "s.json").read_text())
    for measured in ["seconds", "timing"]:
        ours.pop(measured)
        theirs.pop(measured)
    assert ours == theirs
    assert ours["cases"] == 40 and ours["nan"] == 0 and ours["invariant_violations"] == 0


def test_a_stage_s_polygons_are_the_dump_s_as_arrays():
    rec = penumbra.load_scene("default").probe(150, 170, size=(320, 240))
    dump = json.loads(rec.to_json())
    light = dump["recording"]["lights"][0]
    silhouette = next(p for s, p in light["polygons"] if s == "Silhouette")
    loops = rec.polygons(1)
    assert rec.stages[0].startswith("light panel_light: silhouette")
    flat = np.array(silhouette["vertices"], dtype=np.float64)
    assert np.array_equal(np.concatenate(loops), flat)
    assert all(lp.ndim == 2 and lp.shape[1] == 3 and len(lp) >= 3 for lp in loops)
    assert np.allclose(np.linalg.norm(flat, axis=1), 1.0)
    culling = next(i for i, s in enumerate(rec.stages, 1) if "GetBetween" in s)
    assert rec.polygons(culling) == []
    with pytest.raises(ValueError, match="stage 999"):
        rec.polygons(999)


def test_bench_gives_the_cli_rows(tmp_path):
    scene = penumbra.load_scene("default")
    kwargs = dict(size=(32, 24), ladder=[1, 4], methods=["analytic", "mc", "ratio"],
                  reference_spp=64, repeats=1)
    ours = penumbra.bench(scene, **kwargs)
    cli(
        "bench", "default", "--size", "32x24", "--ladder", "1,4", "--methods",
        "analytic,mc,ratio", "--reference-spp", "64", "--repeats", "1", "--out-dir", "b",
        cwd=tmp_path,
    )
    theirs = json.loads((tmp_path / "b" / "bench.json").read_text())["rows"]
    # Times and peak memory are measured, not computed: they differ from run to run.
    measured = {"seconds", "peak_mb"}
    strip = lambda rows: [{k: v for k, v in r.items() if k not in measured} for r in rows]
    assert strip(ours) == strip(theirs)
    assert {"analytic", "mc", "ratio"} <= {r["method"] for r in ours}
    assert all(r["seconds"] > 0 for r in ours)

    # The whole report: the same fields as bench.json, equal but for what the times decide.
    report = penumbra.bench_report(scene, **kwargs)
    whole = json.loads((tmp_path / "b" / "bench.json").read_text())
    assert report.keys() == whole.keys()
    assert strip(report["rows"]) == strip(theirs)
    for key in ["spp", "mean_stderr", "rms_stderr"]:
        assert report["reference"][key] == whole["reference"][key]
    assert report["speed_ratios"]["analytic_seconds"] == min(
        r["seconds"] for r in report["rows"] if r["method"] == "analytic"
    )
    # Its chart is the one the CLI writes: a series per method and the reference's noise.
    chart = penumbra.bench_chart(report)
    assert chart.size == (900, 600)
    for name in ["analytic", "mc", "ratio", "reference noise"]:
        assert f">{name}<" in chart.svg()
        assert f">{name}<" in (tmp_path / "b" / "time_vs_rmse.svg").read_text()
    with pytest.raises(ValueError, match="not a bench report"):
        penumbra.bench_chart({"rows": 3})


def test_the_derivative_comes_with_the_image_and_matches_differences():
    """Oracle: central differences of float64 renders of the moved scene."""
    scene = penumbra.load_scene("default")
    image, rate, mask = scene.render(size=(40, 30), derivative=("sphere", "tx"), mask=True)
    assert image.dtype == np.float64 and rate.dtype == np.float64
    assert image.shape == rate.shape == (30, 40, 3) and mask.shape == (30, 40)
    plain = scene.render(size=(40, 30))
    assert np.allclose(image, plain, rtol=1e-6, atol=1e-7)
    h = 1e-6
    scene.move("sphere", translate=(h, 0.0, 0.0))
    plus, _ = scene.render(size=(40, 30), derivative=("sphere", "tx"))
    scene.move("sphere", translate=(-2 * h, 0.0, 0.0))
    minus, _ = scene.render(size=(40, 30), derivative=("sphere", "tx"))
    fd = (plus - minus) / (2 * h)
    keep = mask == 0
    scale = np.abs(rate[keep]).max()
    assert scale > 0.1
    assert np.abs(rate - fd)[keep].max() < 1e-5 * scale
    with pytest.raises(ValueError, match="analytic"):
        scene.render(method="mc", size=(8, 6), derivative=("sphere", "tx"))
    with pytest.raises(ValueError, match="axis"):
        scene.render(size=(8, 6), derivative=("sphere", "rx"))
