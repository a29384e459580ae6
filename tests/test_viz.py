"""Pictures: the geometry handed to the drawing layer equals FK, images are produced and non-blank
for every catalogue arm, nothing opens a window, workspace figures match closed-form volumes, and the
commands plot/animate/view/workspace behave (JSON, errors on one line with exit code 2)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import denavit
from denavit import Convention, DHLink, DHRobot, JointType, MissingDependencyError
from denavit.cli import main
from denavit.numeric import dh_transform
from denavit.viz import arm_geometry, viewer_html, workspace

from _random_robots import random_robot

NAMES = denavit.catalogue_names()
ATOL = 1e-10


def _frames_by_matrix_product(robot: DHRobot, q: np.ndarray) -> list[np.ndarray]:
    """World frames {0}..{N} by multiplying 4×4 DH matrices (a second route, one configuration)."""
    T = robot.base_matrix
    out = [T]
    k = 0
    for link in robot.links:
        theta, d = link.theta, link.d
        if link.joint is JointType.REVOLUTE:
            theta += q[k]
            k += 1
        elif link.joint is JointType.PRISMATIC:
            d += q[k]
            k += 1
        T = T @ dh_transform(robot.convention, theta, d, link.a, link.alpha)
        out.append(T)
    return out


def _check_geometry(robot: DHRobot, q: np.ndarray) -> None:
    g = arm_geometry(robot, q)
    F = _frames_by_matrix_product(robot, q)
    N = robot.n_rows
    assert g.skeleton.shape == (2 * N + 2, 3)
    for i in range(N + 1):
        np.testing.assert_allclose(g.skeleton[2 * i], F[i][:3, 3], atol=ATOL)
    T_e = F[-1] @ robot.tool_matrix
    np.testing.assert_allclose(g.skeleton[-1], T_e[:3, 3], atol=ATOL)
    np.testing.assert_allclose(g.end_effector, T_e, atol=ATOL)
    # knees: the DH path runs along z by d and along x by a (the two legs of each row)
    d_q, k = [], 0
    for link in robot.links:
        d_q.append(link.d + (q[k] if link.joint is JointType.PRISMATIC else 0.0))
        k += link.is_joint
    for i, link in enumerate(robot.links, start=1):
        knee = g.skeleton[2 * i - 1]
        if robot.convention is Convention.STANDARD:
            np.testing.assert_allclose(knee - F[i - 1][:3, 3], d_q[i - 1] * F[i - 1][:3, 2], atol=ATOL)
            np.testing.assert_allclose(F[i][:3, 3] - knee, link.a * F[i][:3, 0], atol=ATOL)
        else:
            np.testing.assert_allclose(knee - F[i - 1][:3, 3], link.a * F[i - 1][:3, 0], atol=ATOL)
            np.testing.assert_allclose(F[i][:3, 3] - knee, d_q[i - 1] * F[i][:3, 2], atol=ATOL)
    # joints: standard joint i moves about z_{i-1}, modified about z_i (its own row's frame)
    for j, row in enumerate(robot.joint_rows):
        Fj = F[row] if robot.convention is Convention.STANDARD else F[row + 1]
        np.testing.assert_allclose(g.joint_positions[j], Fj[:3, 3], atol=ATOL)
        np.testing.assert_allclose(g.joint_axes[j], Fj[:3, 2], atol=ATOL)
    # triads: origin and the three rotation columns of every frame drawn
    for origin, axes, label in zip(g.triad_origins, g.triad_axes, g.triad_labels):
        want = {"w": np.eye(4), "e": T_e}.get(label)
        want = F[int(label)] if want is None else want
        np.testing.assert_allclose(origin, want[:3, 3], atol=ATOL)
        np.testing.assert_allclose(axes, want[:3, :3].T, atol=ATOL)
    assert set(g.triad_labels) >= {str(i) for i in range(N + 1)}


@pytest.mark.parametrize("name", NAMES)
def test_geometry_equals_fk_for_catalogue(name):
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(abs(hash(name)) % 2**32)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)  # continuous joints (jaco2-6dof): one turn
    for _ in range(3):
        _check_geometry(robot, rng.uniform(lim[:, 0], lim[:, 1]))


@pytest.mark.parametrize("seed", range(12))
def test_geometry_equals_fk_for_random_robots(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng)
    _check_geometry(robot, rng.uniform(-np.pi, np.pi, robot.dof))


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_geometry_batch_equals_loop(shape):
    rng = np.random.default_rng(5)
    robot = random_robot(rng, convention="modified", n_rows=5)
    q = rng.uniform(-np.pi, np.pi, shape + (robot.dof,))
    g = arm_geometry(robot, q)
    assert g.skeleton.shape == shape + (2 * robot.n_rows + 2, 3)
    for idx in np.ndindex(*shape):
        one = arm_geometry(robot, q[idx])
        np.testing.assert_allclose(g.skeleton[idx], one.skeleton, atol=1e-12)
        np.testing.assert_allclose(g.joint_frames[idx], one.joint_frames, atol=1e-12)
        np.testing.assert_allclose(g.triad_axes[idx], one.triad_axes, atol=1e-12)


# ---- images -----------------------------------------------------------------------------------------

def _png_pixels(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), dtype=float)


def _assert_not_blank(pixels: np.ndarray) -> None:
    assert pixels.std() > 10.0, "image looks blank"
    ink = (np.abs(pixels - 255).sum(axis=-1) > 60).mean()
    assert ink > 0.01, f"only {ink:.3%} of the pixels are drawn"


@pytest.mark.parametrize("name", NAMES)
def test_plot_every_catalogue_arm_png_not_blank_and_drawn_from_fk(name, tmp_path):
    pytest.importorskip("matplotlib")
    from denavit.viz import plot_robot, save_figure

    robot = denavit.load_robot(name)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)  # continuous joints (jaco2-6dof): one turn
    q = np.random.default_rng(1).uniform(lim[:, 0], lim[:, 1])
    fig = plot_robot(robot, q, path=np.linspace(q, (lim[:, 0] + lim[:, 1]) / 2, 12))
    ax = fig.axes[0]
    # the thick centre line the picture shows is the FK chain (data read back from the artist)
    skel = np.column_stack(ax.lines[0].get_data_3d())
    frames = denavit.link_transforms(robot, q)
    np.testing.assert_allclose(skel[0:-1:2], frames[:, :3, 3], atol=ATOL)
    np.testing.assert_allclose(skel[-1], denavit.forward_kinematics(robot, q)[:3, 3], atol=ATOL)
    # equal scaling: the three axis ranges have the same length
    spans = [float(np.diff(lim_)[0]) for lim_ in (ax.get_xlim(), ax.get_ylim(), ax.get_zlim())]
    np.testing.assert_allclose(spans, spans[0], rtol=1e-9)
    out = save_figure(fig, tmp_path / f"{name}.png")
    _assert_not_blank(_png_pixels(out))


def test_plot_vector_formats_and_user_axes(tmp_path):
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure

    from denavit.viz import plot_robot, save_figure

    robot = denavit.load_robot("stanford")
    fig = plot_robot(robot, [0.2, -0.4, 0.6, 0.1, 0.5, 0.0], frames=False)
    assert save_figure(fig, tmp_path / "a.svg").read_text().lstrip().startswith(("<?xml", "<svg"))
    assert save_figure(fig, tmp_path / "a.pdf").read_bytes().startswith(b"%PDF")
    user = Figure()
    ax = user.add_subplot(1, 2, 2, projection="3d")
    assert plot_robot(robot, None, ax=ax) is user
    assert len(ax.lines) > 0
    with pytest.raises(denavit.ParseError, match="unsupported picture format"):
        save_figure(fig, tmp_path / "a.bmp")


def _run_python(code: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "MPLBACKEND", "WAYLAND_DISPLAY")}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)


def test_headless_without_pyplot_and_lazy_import(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "arm.png"
    code = f"""
import sys, denavit, denavit.viz
assert 'matplotlib' not in sys.modules, 'import denavit.viz loaded matplotlib'
fig = denavit.viz.plot_robot(denavit.load_robot('puma560'))
denavit.viz.save_figure(fig, {str(out)!r})
assert 'matplotlib.pyplot' not in sys.modules, 'pyplot was imported'
print('ok')
"""
    r = _run_python(code)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr
    _assert_not_blank(_png_pixels(out))


def test_missing_matplotlib_names_the_extra(tmp_path):
    code = f"""
import sys
sys.modules['matplotlib'] = None  # as if not installed
import denavit, denavit.viz
try:
    denavit.viz.plot_robot(denavit.load_robot('planar2r'))
except denavit.MissingDependencyError as e:
    print('MDE', e)
from denavit.cli import main
sys.exit(main(['plot', 'planar2r', '-o', {str(tmp_path / 'x.png')!r}]))
"""
    r = _run_python(code)
    assert "MDE" in r.stdout and "denavit[plot]" in r.stdout
    assert r.returncode == 1
    assert len(r.stderr.strip().splitlines()) == 1 and "denavit[plot]" in r.stderr
    assert issubclass(MissingDependencyError, ImportError)


# ---- animation ---------------------------------------------------------------------------------------

def test_animate_gif_frames(tmp_path):
    pytest.importorskip("matplotlib")
    from PIL import Image

    from denavit.numeric import quintic_trajectory
    from denavit.viz import animate_robot

    robot = denavit.load_robot("scara")
    tr = quintic_trajectory([0.0, 0.0, 0.05, 0.0], [0.6, 1.0, 0.18, 1.5], 6)
    out = animate_robot(robot, tr.q, tmp_path / "m.gif", fps=10, frames=False)
    with Image.open(out) as im:
        assert im.n_frames == 6
        im.seek(0)
        first = np.asarray(im.convert("RGB"), dtype=float)
        im.seek(5)
        last = np.asarray(im.convert("RGB"), dtype=float)
    _assert_not_blank(first)
    assert np.abs(first - last).sum(axis=-1).astype(bool).mean() > 0.005, "the arm did not move"



@pytest.mark.parametrize("name", ["puma560", "ur5", "planar3r", "scara"])
def test_animation_frames_are_large_and_nothing_is_clipped(tmp_path, name):
    """GIF frames are at least 600 px square and the drawing (arm, ticks, the z [m] label) keeps off the
    right and bottom edges: a clipped label would leave ink in the outermost pixel columns or rows."""
    pytest.importorskip("matplotlib")
    from PIL import Image

    from denavit.viz import animate_robot

    robot = denavit.load_robot(name)
    rng = np.random.default_rng(7)
    lo, hi = np.maximum(robot.q_limits.T[0], -np.pi), np.minimum(robot.q_limits.T[1], np.pi)
    out = animate_robot(robot, rng.uniform(lo, hi, (2, robot.dof)), tmp_path / "m.gif", fps=5)
    with Image.open(out) as im:
        assert min(im.size) >= 600
        for k in range(im.n_frames):
            im.seek(k)
            ink = np.asarray(im.convert("L"), dtype=float) < 160  # (h, w): dark pixels: text, lines, arm
            h, w = ink.shape
            margin = int(0.01 * w)
            assert not ink[:, w - margin:].any() and not ink[h - margin:, :].any(), f"drawing clipped, frame {k}"
            assert not ink[:, :margin].any()


# ---- workspace ----------------------------------------------------------------------------------------

def test_workspace_planar_2r_area_is_the_disc():
    robot = denavit.load_robot("planar2r")
    L1, L2 = abs(robot.links[0].a), abs(robot.links[1].a)
    ws = workspace(robot, 200_000, resolution=0.05, rng=np.random.default_rng(0))
    assert ws.planar and ws.volume == 0.0
    exact = np.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2)  # annulus; a disc when L1 = L2
    assert ws.area == pytest.approx(exact, rel=0.08)
    assert ws.reach == pytest.approx(L1 + L2, abs=2e-3)
    assert np.all(np.linalg.norm(ws.points, axis=-1) <= L1 + L2 + 1e-12)


def test_workspace_cylindrical_rpp_volume():
    """RPP arm (seed report 004, arm 5): d2 ∈ [0, 0.5] lifts, d3 ∈ [0.1, 0.6] extends radially."""
    robot = denavit.load_robot("report004-5-rpp-cylindrical")
    (h0, h1), (r0, r1) = robot.joints[1].q_limits, robot.joints[2].q_limits
    ws = workspace(robot, 200_000, resolution=0.025, rng=np.random.default_rng(1))
    exact = np.pi * (r1**2 - r0**2) * (h1 - h0)
    assert not ws.planar
    assert ws.volume == pytest.approx(exact, rel=0.08)
    np.testing.assert_allclose(ws.extent, [2 * r1, 2 * r1, h1 - h0], rtol=0.02)


def test_workspace_spherical_shell_volume():
    """RRP arm with full turns: the tip sweeps the shell r0 ≤ |p| ≤ r1 (volume 4π(r1³ − r0³)/3)."""
    r0, r1 = 0.3, 0.8
    robot = DHRobot("sph", (
        DHLink(alpha=np.pi / 2, q_limits=(-np.pi, np.pi)),
        DHLink(alpha=np.pi / 2, q_limits=(-np.pi, np.pi), theta=np.pi / 2),
        DHLink(joint=JointType.PRISMATIC, q_limits=(r0, r1)),
    ))
    ws = workspace(robot, 400_000, resolution=0.05, rng=np.random.default_rng(2))
    radii = np.linalg.norm(ws.points, axis=-1)
    assert radii.min() >= r0 - 1e-12 and radii.max() <= r1 + 1e-12
    exact = 4 / 3 * np.pi * (r1**3 - r0**3)
    assert ws.volume == pytest.approx(exact, rel=0.15)


def test_workspace_is_repeatable_with_a_seed():
    robot = denavit.load_robot("puma560")
    a = workspace(robot, 5000, rng=np.random.default_rng(3))
    b = workspace(robot, 5000, rng=np.random.default_rng(3))
    np.testing.assert_array_equal(a.points, b.points)
    lim = robot.q_limits
    assert a.voxels == b.voxels and a.volume > 0 and np.all(a.extent > 0) and lim.shape == (6, 2)


# ---- HTML page (content; the browser test drives it) -------------------------------------------------

def test_viewer_page_is_self_contained_and_embeds_the_table():
    robot = denavit.load_robot("stanford")
    page = viewer_html(robot)
    assert "http://" not in page and "https://" not in page and "<link" not in page
    assert page.count('type="range"') == robot.dof
    start = page.index('id="denavit-data">') + len('id="denavit-data">')
    data = json.loads(page[start:page.index("</script>", start)])
    assert data["convention"] == "standard" and len(data["rows"]) == robot.n_rows
    np.testing.assert_allclose(data["limits"], robot.q_limits)
    np.testing.assert_allclose([r["a"] for r in data["rows"]], [link.a for link in robot.links])
    hostile = robot.replace(name="</script><script>alert(1)</script>")
    hostile_page = viewer_html(hostile)
    assert "<script>alert(1)" not in hostile_page and hostile_page.count("<script") == 2


# ---- command line ----------------------------------------------------------------------------------------

def _cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_plot_json_and_file(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "arm.png"
    code, stdout, err = _cli(capsys, "plot", "puma560", "-q", "0, 45, -90, 0, 45, 0", "--deg", "-o", str(out),
                             "--json", "--path-to", "10, 50, -80, 0, 40, 10")
    assert code == 0, err
    data = json.loads(stdout)
    q = np.radians([0, 45, -90, 0, 45, 0])
    np.testing.assert_allclose(data["q"], np.degrees(q))
    robot = denavit.load_robot("puma560")
    np.testing.assert_allclose(data["T"], denavit.forward_kinematics(robot, q), atol=1e-12)
    np.testing.assert_allclose(data["joint_positions"][0], denavit.link_transforms(robot, q)[0, :3, 3], atol=1e-12)
    _assert_not_blank(_png_pixels(out))


@pytest.mark.slow
def test_cli_animate_view_workspace(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    code, stdout, err = _cli(capsys, "animate", "planar3r", "--from", "0, 0.5, 0.5", "--to", "1, 1, -0.5",
                             "-o", str(tmp_path / "m.gif"), "--profile", "cartesian", "--duration", "0.4",
                             "--fps", "10", "--json")
    assert code == 0, err
    data = json.loads(stdout)
    assert data["frames"] == 5 and data["success"] is True and (tmp_path / "m.gif").stat().st_size > 0
    p = np.array(data["end_effector_path"])
    d = p[-1] - p[0]
    rel = p - p[0]
    assert np.abs(np.cross(rel, d)).max() < 1e-6 * np.linalg.norm(d)

    code, stdout, err = _cli(capsys, "view", "ur5", "-o", str(tmp_path / "v.html"), "--json")
    assert code == 0, err
    assert json.loads(stdout)["bytes"] == (tmp_path / "v.html").stat().st_size

    code, stdout, err = _cli(capsys, "workspace", "scara", "-o", str(tmp_path / "w.png"), "--samples", "3000",
                             "--seed", "4", "--json")
    assert code == 0, err
    data = json.loads(stdout)
    for key in ("bounds_min", "bounds_max", "extent", "volume", "resolution", "voxels", "reach", "samples"):
        assert key in data
    assert data["volume"] > 0 and data["samples"] == 3000
    _assert_not_blank(_png_pixels(tmp_path / "w.png"))


@pytest.mark.parametrize("argv,fragment", [
    (["plot", "puma560", "-q", "1, 2", "-o", "{tmp}/a.png"], "expected 6 values"),
    (["plot", "puma560", "-o", "{tmp}/a.jpg"], "'.jpg'"),
    (["plot", "puma560", "-o", "{tmp}/missing/a.png"], "does not exist"),
    (["plot", "puma560", "-q", "0, 0, 0, 0, 0, 9", "-o", "{tmp}/a.png"], "outside its limits"),
    (["animate", "planar2r", "--from", "0, 0", "--to", "1, x", "-o", "{tmp}/a.gif"], "--to"),
    (["animate", "planar2r", "--from", "0, 0", "--to", "1, 1", "-o", "{tmp}/a.gif", "--duration", "-1"], "--duration"),
    (["animate", "planar2r", "--from", "0, 0", "--to", "1, 1", "-o", "{tmp}/a.png"], "unsupported"),
    (["view", "puma560", "-o", "{tmp}/a.txt"], ".html"),
    (["view", "{tmp}/nope.yaml", "-o", "{tmp}/a.html"], "nope.yaml"),
    (["workspace", "puma560", "--samples", "5"], "--samples"),
    (["workspace", "puma560", "--resolution", "0"], "--resolution"),
])
def test_cli_bad_input_is_one_line_exit_2(argv, fragment, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    code, out, err = _cli(capsys, *[a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and fragment in err and "Traceback" not in err


@pytest.mark.slow
def test_animate_mp4_when_ffmpeg_exists(tmp_path):
    """MP4 goes through ffmpeg: the file has the requested number of frames (read back with ffprobe)."""
    import shutil
    import subprocess

    if shutil.which("ffmpeg") is None or shutil.which("ffprobe") is None:
        pytest.skip("ffmpeg not installed (MP4 output needs it; GIF does not)")
    from denavit.cli import main

    out = tmp_path / "move.mp4"
    assert main(["animate", "planar2r", "--from", "0, 0", "--to", "1, 1", "--duration", "1", "--fps", "12",
                 "-o", str(out)]) == 0
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=nb_read_frames,codec_name", "-of", "csv=p=0", str(out)],
                           capture_output=True, text=True, check=True).stdout.strip()
    codec, frames = probe.split(",")
    assert codec and int(frames) == 13  # 1 s at 12 fps, both end points


def test_workspace_pictures_explain_their_colours():
    """The point cloud's colours (height) and the occupancy pictures' (log sample count) each have a colour bar."""
    from denavit import scale
    from denavit.viz import plot_occupancy, plot_workspace, workspace

    robot = denavit.load_robot("puma560")
    fig = plot_workspace(workspace(robot, samples=2000, rng=np.random.default_rng(0)), "puma560")
    assert any(ax.get_ylabel() == "height z [m]" for ax in fig.axes)
    for name in ("puma560", "planar2r"):
        fig = plot_occupancy(scale.occupancy(denavit.load_robot(name), samples=20_000, seed=1), name)
        bars = [ax for ax in fig.axes if "samples per cell" in ax.get_ylabel()]
        assert len(bars) == 1  # one scale for every panel
