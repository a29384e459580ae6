"""The workbench's server (``denavit serve``): its JSON endpoints through Starlette's TestClient, its jobs, and the
command itself.  Truth comes from routes independent of the code under test: the DH product written out here,
central differences of it for the Jacobian, the closed-form dynamics of the planar elbow arm (Spong et al. 2006,
Sec. 7.4, point masses at the link ends), and a report whose right and wrong lines are known by hand."""

from __future__ import annotations

import json
import math
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest

import denavit

pytest.importorskip("starlette")
pytest.importorskip("httpx")

from starlette.testclient import TestClient

from denavit.cli import main
from denavit.web import MAX_RUNNING, Jobs, claim_lines, create_app

PLANAR = {"name": "two-link", "convention": "standard", "parameters": {"L1": "0.7", "L2": "0.4"},
          "joints": [{"a": "L1", "alpha": 0, "d": 0, "theta": "q"}, {"a": "L2", "alpha": 0, "d": 0, "theta": "q"}]}
POSTS = ["/api/robot", "/api/kinematics", "/api/ik", "/api/dynamics", "/api/statics", "/api/table",
         "/api/catalogue/load", "/api/robot-file", "/api/open", "/api/jobs"]


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(allowed_hosts=["testserver"], jobs=Jobs(cpu_seconds=120))) as c:
        yield c


def _dh(rows, q, convention="standard"):
    """T_0_n by the DH product written out here (Spong 2006 eq. 3.10 / Craig 2005 eq. 3.6), rows (a, α, d, θ, kind)."""
    T, k = np.eye(4), 0
    for a, al, d, th, kind in rows:
        if kind == "R":
            th, k = th + q[k], k + 1
        elif kind == "P":
            d, k = d + q[k], k + 1
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        if convention == "standard":
            A = np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])
        else:
            A = np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d], [st * sa, ct * sa, ca, ca * d], [0, 0, 0, 1]])
        T = T @ A
    return T


def _one_line_error(r, status):
    assert r.status_code == status, r.text
    err = r.json()["error"]
    assert err and "\n" not in err and len(err) <= 400
    return r.json()


def test_kinematics_of_an_edited_table_match_the_dh_product_and_differences(client):
    doc = json.loads(json.dumps(PLANAR))
    doc["joints"].append({"a": 0, "alpha": "pi/2", "d": "q + 0.1", "theta": "pi/6"})  # a prismatic row
    info = client.post("/api/robot", json={"robot": doc}).json()
    assert info["rows"] == ["revolute", "revolute", "prismatic"] and info["dof"] == 3
    rows = [(0.7, 0, 0, 0, "R"), (0.4, 0, 0, 0, "R"), (0, math.pi / 2, 0.1, math.pi / 6, "P")]
    q = np.array([0.3, -1.1, 0.25])
    r = client.post("/api/kinematics", json={"robot": doc, "q": q.tolist(), "seq": 7}).json()
    assert r["seq"] == 7
    np.testing.assert_allclose(r["T"], _dh(rows, q), atol=1e-12)
    h = 1e-6  # linear rows of J0 = ∂p/∂q by central differences of the product
    Jv = np.column_stack([(_dh(rows, q + h * e)[:3, 3] - _dh(rows, q - h * e)[:3, 3]) / (2 * h) for e in np.eye(3)])
    np.testing.assert_allclose(np.array(r["J"])[:3], Jv, atol=1e-8)
    J = np.array(r["J"])
    assert r["det"] is None and r["manipulability"] == pytest.approx(math.sqrt(np.linalg.det(J @ J.T)), abs=1e-12)


def test_measures_on_task_rows_det_of_the_planar_arm(client):
    """Planar 2R on its task rows (vx, vy): det J = a1 a2 sin q2 (Spong 2006 Sec. 4.9); on all six rows J Jᵀ is
    singular and Yoshikawa's w is 0."""
    q = [0.3, 1.1]
    r = client.post("/api/kinematics", json={"robot": PLANAR, "q": q, "rows": ["vx", "vy"]}).json()
    assert r["rows"] == ["vx", "vy"]
    assert r["det"] == pytest.approx(0.7 * 0.4 * math.sin(1.1), abs=1e-12)
    assert r["manipulability"] == pytest.approx(abs(r["det"]), abs=1e-12)
    r6 = client.post("/api/kinematics", json={"robot": PLANAR, "q": q}).json()
    assert r6["rows"] == ["vx", "vy", "vz", "wx", "wy", "wz"] and r6["manipulability"] == 0 and r6["det"] is None
    _one_line_error(client.post("/api/kinematics", json={"robot": PLANAR, "q": q, "rows": ["vx", "up"]}), 422)


def test_a_bad_cell_is_named_by_row_and_field(client):
    doc = json.loads(json.dumps(PLANAR))
    doc["joints"][1]["theta"] = "q + sin("
    err = _one_line_error(client.post("/api/robot", json={"robot": doc}), 422)
    assert err["cell"] == {"row": 2, "field": "theta"}
    doc["joints"][1]["theta"] = "q"
    doc["joints"][0]["alpha"] = "q"  # the variable where it may not be
    assert _one_line_error(client.post("/api/robot", json={"robot": doc}), 422)["cell"] == {"row": 1, "field": "alpha"}
    doc["joints"][0]["alpha"] = 0
    doc["parameters"]["L1"] = "__import__('os')"
    assert _one_line_error(client.post("/api/robot", json={"robot": doc}), 422)["cell"]["field"] == "parameters"


def test_every_ik_solution_reaches_the_target_and_includes_the_start(client):
    doc = client.post("/api/catalogue/load", json={"name": "puma560"}).json()["robot"]
    q = np.array([0.2, 0.5, -0.9, 0.4, 0.7, -0.3])
    r = client.post("/api/ik", json={"robot": doc, "q": q.tolist()}).json()
    assert len(r["solutions"]) >= 2
    Tq = client.post("/api/kinematics", json={"robot": doc, "q": q.tolist()}).json()["T"]
    for s in r["solutions"]:
        Ts = client.post("/api/kinematics", json={"robot": doc, "q": s["q"]}).json()["T"]
        np.testing.assert_allclose(Ts, Tq, atol=1e-9)
    assert min(np.abs(np.array(s["q"]) - q).max() for s in r["solutions"]) < 1e-9
    # a typed target: x, y, z, roll, pitch, yaw (rpy = Rz(yaw) Ry(pitch) Rx(roll))
    r = client.post("/api/ik", json={"robot": doc, "pose": "0.5, 0.1, 0.6, 0, 90deg, 0"}).json()
    assert r["solutions"]
    np.testing.assert_allclose(np.array(r["target"])[:3, 3], [0.5, 0.1, 0.6], atol=1e-12)
    np.testing.assert_allclose(np.array(r["target"])[:3, 2], [1, 0, 0], atol=1e-12)  # Ry(90°) z = x


def test_a_redundant_arm_is_solved_with_a_held_joint(client):
    panda = client.post("/api/catalogue/load", json={"name": "panda"}).json()["robot"]
    q = [0.1, 0.2, 0.3, -1.4, 0.5, 1.6, 0.7]
    err = _one_line_error(client.post("/api/ik", json={"robot": panda, "q": q}), 422)
    assert "redundant" in err["error"]
    r = client.post("/api/ik", json={"robot": panda, "q": q, "lock": "q7"}).json()
    Tq = client.post("/api/kinematics", json={"robot": panda, "q": q}).json()["T"]
    assert r["solutions"] and all(s["q"][6] == pytest.approx(0.7, abs=1e-12) for s in r["solutions"])
    for s in r["solutions"]:
        np.testing.assert_allclose(client.post("/api/kinematics", json={"robot": panda, "q": s["q"]}).json()["T"], Tq,
                                   atol=1e-9)
    assert min(np.abs(np.array(s["q"]) - q).max() for s in r["solutions"]) < 1e-9
    for bad in ("q9", "x7", "q7 = pi/", "q0"):
        _one_line_error(client.post("/api/ik", json={"robot": panda, "q": q, "lock": bad}), 422)


def test_numeric_ik_of_a_seven_joint_arm_from_the_sliders_and_a_shifted_target(client):
    """panda has no closed form for its 7 joints: the numeric answer (Levenberg–Marquardt from the seed) reaches the
    pose of another configuration within the solver's tolerance, by FK computed here; a target shifted by the
    drag pad is the pose at q moved along world axes."""
    from denavit.ik import TOL

    panda = client.post("/api/catalogue/load", json={"name": "panda"}).json()["robot"]
    assert client.post("/api/robot", json={"robot": panda}).json()["analytic_ik"] is False
    robot = denavit.robot_from_dict(panda)
    qb, seed = [0.3, -0.4, 0.2, -1.8, 0.1, 1.6, 0.5], [0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0]
    r = client.post("/api/ik", json={"robot": panda, "q": qb, "seed": seed, "method": "numeric"}).json()
    assert len(r["solutions"]) == 1 and r["solutions"][0]["valid"] and r["method"].startswith("numeric")
    sol = np.array(r["solutions"][0]["q"])
    assert np.abs(sol - qb).max() > 1e-3  # found from the seed, not handed back
    Tb = denavit.forward_kinematics(robot, qb)
    Ts = denavit.forward_kinematics(robot, sol)
    assert np.linalg.norm(Ts[:3, 3] - Tb[:3, 3]) <= TOL
    assert np.linalg.norm(Ts[:3, :3] - Tb[:3, :3]) <= 10 * TOL  # ‖ΔR‖_F ≈ √2 |angle| for a small rotation
    r = client.post("/api/ik", json={"robot": panda, "q": qb, "shift": "0.1, 0, -0.05", "method": "numeric"}).json()
    np.testing.assert_allclose(np.array(r["target"])[:3, 3], Tb[:3, 3] + [0.1, 0, -0.05], atol=1e-12)
    np.testing.assert_allclose(np.array(r["target"])[:3, :3], Tb[:3, :3], atol=1e-12)
    assert r["solutions"] and np.allclose(denavit.forward_kinematics(robot, r["solutions"][0]["q"]), r["target"],
                                          atol=1e-8)
    assert client.post("/api/robot", json={"robot": client.post("/api/catalogue/load", json={"name": "puma560"})
                                           .json()["robot"]}).json()["analytic_ik"] is True
    for bad in ({"method": "guess"}, {"shift": "1, 2"}, {"shift": "1e4, 0, 0"}, {"seed": [1, 2]}):
        _one_line_error(client.post("/api/ik", json={"robot": panda, "q": qb, "method": "numeric", **bad}), 422)


def test_dynamics_match_the_closed_form_planar_elbow_and_statics_the_transpose(client):
    doc = client.post("/api/catalogue/load", json={"name": "planar2r"}).json()["robot"]  # L = m = 1, g along -y
    q, qd = np.array([0.4, -0.9]), np.array([0.7, -0.2])
    r = client.post("/api/dynamics", json={"robot": doc, "q": q.tolist(), "qd": "0.7, -0.2"}).json()
    c2, s2, g0 = math.cos(q[1]), math.sin(q[1]), 9.81
    M = [[3 + 2 * c2, 1 + c2], [1 + c2, 1]]  # m1 L1² + m2 (L1² + 2 L1 L2 c2 + L2²), ...
    c = [-s2 * (2 * qd[0] * qd[1] + qd[1] ** 2), s2 * qd[0] ** 2]
    g = [2 * g0 * math.cos(q[0]) + g0 * math.cos(q[0] + q[1]), g0 * math.cos(q[0] + q[1])]
    np.testing.assert_allclose(r["M"], M, atol=1e-12)
    np.testing.assert_allclose(r["c"], c, atol=1e-12)
    np.testing.assert_allclose(r["g"], g, atol=1e-12)
    w = np.array([3.0, -2.0, 0, 0, 0, 0.5])
    tau = client.post("/api/statics", json={"robot": doc, "q": q.tolist(), "wrench": "3, -2, 0, 0, 0, 0.5"}).json()["tau"]
    rows = [(1, 0, 0, 0, "R"), (1, 0, 0, 0, "R")]
    h = 1e-6
    Jv = np.column_stack([(_dh(rows, q + h * e)[:3, 3] - _dh(rows, q - h * e)[:3, 3]) / (2 * h) for e in np.eye(2)])
    np.testing.assert_allclose(tau, Jv.T @ w[:3] + w[5] * np.ones(2), atol=1e-8)  # planar: ω = q̇1 + q̇2 about z


def test_an_ik_answer_runs_off_the_event_loop_so_slider_answers_still_come(monkeypatch):
    """The general-6R IK takes tenths of a second: while one is held (here: until the test lets it go), the
    kinematics answers of the sliders keep coming on the one event loop."""
    import threading

    from denavit.web import _ik

    release, entered, out = threading.Event(), threading.Event(), {}
    real = _ik.inverse_kinematics

    def held(body):
        entered.set()
        release.wait(timeout=60)
        return real(body)

    monkeypatch.setattr(_ik, "inverse_kinematics", held)
    jobs = Jobs()
    jobs.warm_up = lambda: None  # no fork server needed here
    with TestClient(create_app(allowed_hosts=["testserver"], jobs=jobs)) as c:  # one event loop for all requests
        t = threading.Thread(target=lambda: out.setdefault("ik", c.post("/api/ik", json={"robot": PLANAR, "q": [0.3, 0.5]})))
        t.start()
        assert entered.wait(timeout=60)
        answers = [c.post("/api/kinematics", json={"robot": PLANAR, "q": [0.1 * k, 0.2]}).status_code for k in range(5)]
        held_meanwhile = "ik" not in out
        release.set()
        t.join(timeout=60)
    assert answers == [200] * 5 and held_meanwhile
    assert out["ik"].status_code == 200 and len(out["ik"].json()["solutions"]) == 2  # elbow up and down


def test_a_pasted_table_becomes_a_robot_with_its_notes(client):
    text = "| i | a_{i-1} | alpha_{i-1} | d_i | theta_i |\n|---|---|---|---|---|\n| 1 | 0 | 0 | 0 | theta_1 |\n" \
           "| 2 | 0.5 | 90 | 0 | theta_2 |\n"
    r = client.post("/api/table", json={"text": text}).json()
    assert r["robot"]["convention"] == "modified" and any("degrees" in n for n in r["notes"])
    q = [0.3, 0.8]
    T = client.post("/api/kinematics", json={"robot": r["robot"], "q": q}).json()["T"]
    np.testing.assert_allclose(T, _dh([(0, 0, 0, 0, "R"), (0.5, math.pi / 2, 0, 0, "R")], q, "modified"), atol=1e-12)
    _one_line_error(client.post("/api/table", json={"text": "no table here"}), 422)


def test_catalogue_names_only_never_paths_and_the_robot_file_loads_back(client, tmp_path):
    names = client.get("/api/catalogue").json()["names"]
    assert "puma560" in names
    for bad in ["../../../etc/passwd", "/etc/passwd", "puma560.yaml", 5, None]:
        _one_line_error(client.post("/api/catalogue/load", json={"name": bad}), 404)
    r = client.post("/api/robot-file", json={"robot": PLANAR}).json()
    path = tmp_path / r["filename"]
    path.write_text(r["text"], encoding="utf-8")
    from denavit import forward_kinematics, load_robot

    np.testing.assert_allclose(forward_kinematics(load_robot(path), [0.2, 0.3]),
                               _dh([(0.7, 0, 0, 0, "R"), (0.4, 0, 0, 0, "R")], [0.2, 0.3]), atol=1e-12)


def test_an_opened_robot_file_keeps_its_cells_a_urdf_becomes_rows_and_no_text_is_a_path(client, tmp_path):
    text = "convention: modified\nparameters: {L: 0.5}\njoints:\n  - {a: 0, alpha: 0, d: 0, theta: q}\n" \
           "  - {a: L, alpha: pi/2, d: 0, theta: q + pi/2}\n"
    r = client.post("/api/open", json={"text": text, "filename": "arm.yaml"}).json()
    assert r["robot"]["joints"][1] == {"a": "L", "alpha": "pi/2", "d": 0, "theta": "q + pi/2"}  # as written
    q = [0.3, -0.4]
    T = client.post("/api/kinematics", json={"robot": r["robot"], "q": q}).json()["T"]
    np.testing.assert_allclose(T, _dh([(0, 0, 0, 0, "R"), (0.5, math.pi / 2, 0, math.pi / 2, "R")], q, "modified"),
                               atol=1e-12)
    urdf = ('<robot name="r1"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>'
            '<child link="b"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint></robot>')
    r = client.post("/api/open", json={"text": urdf, "filename": "r1.urdf"}).json()
    T = client.post("/api/kinematics", json={"robot": r["robot"], "q": [0.7]}).json()["T"]
    np.testing.assert_allclose(np.array(T)[:3, 3], [0, 0, 0.5], atol=1e-12)  # a joint 0.5 m up, turning about z
    np.testing.assert_allclose(np.array(T)[:2, 0], [math.cos(0.7), math.sin(0.7)], atol=1e-12)
    secret = tmp_path / "secret.urdf"
    secret.write_text(urdf, encoding="utf-8")
    for name in ("x.urdf", "x.yaml", "x.exe"):  # a path as the text is text, never opened
        _one_line_error(client.post("/api/open", json={"text": str(secret), "filename": name}), 422)
    err = _one_line_error(client.post("/api/open", json={"text": text.replace("pi/2}", "pi/"), "filename": "a.yaml"}), 422)
    assert "a.yaml" in err["error"]
    bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
                                                         for p, c in zip("abcdefg", "bcdefgh"))
    _one_line_error(client.post("/api/open", json={"text": bomb, "filename": "bomb.yaml"}), 422)


def test_the_workspace_job_of_the_planar_elbow_arm_is_the_disk_of_radius_two(client):
    pytest.importorskip("matplotlib")
    doc = client.post("/api/catalogue/load", json={"name": "planar2r"}).json()["robot"]  # L1 = L2 = 1, full turns
    s = _wait(client, client.post("/api/jobs", json={"kind": "workspace", "payload": {"robot": doc, "samples": 20000}}
                                  ).json()["id"])
    assert s["state"] == "done", s
    res = s["result"]
    assert res["planar"] and 1.99 < res["reach"] <= 2 + 1e-12
    assert abs(res["area"] - 4 * math.pi) < 0.15 * 4 * math.pi  # pixel counting of the disk r <= L1 + L2
    import base64

    assert base64.b64decode(res["png"])[:8] == b"\x89PNG\r\n\x1a\n"
    assert res["low"] <= res["area"] <= res["high"] and res["volume"] is None
    err = client.post("/api/jobs", json={"kind": "workspace", "payload": {"robot": doc, "samples": 10**10}}).json()
    assert _wait(client, err["id"])["error"].startswith("'samples' must be")


def test_the_singular_sets_of_the_planar_elbow_arm_are_stretched_and_folded(client):
    """det J = L1 L2 sin q2 for the planar elbow arm (Spong 2006 Sec. 4.9): singular at q2 = 0 and q2 = π only."""
    s = _wait(client, client.post("/api/jobs", json={"kind": "singularities", "payload": {"robot": PLANAR}}).json()["id"])
    assert s["state"] == "done", s
    conds = s["result"]["conditions"]
    values = sorted(v for c in conds for x in c["solutions"] for v in x["values"] if x["variable"] == "q2")
    assert [x["variable"] for c in conds for x in c["solutions"]] == ["q2"] * len(values)
    np.testing.assert_allclose(values, [0, math.pi], atol=1e-12)


def test_bodies_are_bounded_typed_and_json(client):
    big = b'{"robot": "' + b"x" * 300_000 + b'"}'
    _one_line_error(client.post("/api/robot", content=big, headers={"Content-Type": "application/json"}), 413)
    _one_line_error(client.post("/api/robot", content=b'{"robot": 1}', headers={"Content-Type": "text/plain"}), 415)
    deep = b"[" * 100_000 + b"]" * 100_000
    _one_line_error(client.post("/api/kinematics", content=deep, headers={"Content-Type": "application/json"}), 400)
    _one_line_error(client.post("/api/kinematics", content=b'{"q": NaN}', headers={"Content-Type": "application/json"}), 400)
    _one_line_error(client.get("/etc/passwd"), 404)
    _one_line_error(client.get("/static/..%2F_app.py"), 404)
    assert client.get("/", headers={"Host": "evil.example"}).status_code == 400  # DNS rebinding: wrong Host
    page = client.get("/")
    assert page.status_code == 200 and '"two-link"' not in page.text and "puma560" in page.text


def test_hostile_bodies_get_one_line_4xx_never_500(client):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    leaf = st.none() | st.booleans() | st.integers(-10**30, 10**30) | st.floats() | st.text(max_size=30)
    value = st.recursive(leaf, lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=8), inner,
                                                                                               max_size=5), max_leaves=20)
    cell = st.sampled_from(["q", "0", "pi/2", "L1", "q + q", "1e400", "nan", "sin(", "deg(90)", "", "q2", "__class__",
                            "a" * 300]) | value
    keys = st.sampled_from(["robot", "q", "qd", "pose", "wrench", "frame", "text", "name", "format", "kind", "payload",
                            "filename", "shift", "seed", "method", "lock"])

    @settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
    @given(path=st.sampled_from(POSTS), body=st.dictionaries(keys, value, max_size=4) | value,
           row=st.integers(0, 1), field=st.sampled_from(["a", "alpha", "d", "theta", "limits"]), text=cell)
    def hostile(path, body, row, field, text):
        doc = json.loads(json.dumps(PLANAR))
        doc["joints"][row][field] = text
        for b in (body, {"robot": doc, "q": [0.1, 0.2], "pose": "0.5, 0, 0, 0, 0, 0", "qd": text, "wrench": text},
                  {"robot": PLANAR, "q": [0.1, 0.2], "method": "numeric", "shift": text, "seed": text}):
            r = client.post(path, content=json.dumps(b, allow_nan=True), headers={"Content-Type": "application/json"})
            assert r.status_code < 500, (path, b, r.text)
            if r.status_code >= 400:
                _one_line_error(r, r.status_code)
            elif path == "/api/jobs":
                client.post(f"/api/jobs/{r.json()['id']}/cancel")

    hostile()


def _exit_code(client, job_id, seconds=60.0):
    """The job process's exit code as the server's reader thread recorded it (the only thread that joins it: a
    forkserver child's exit status is one message, so a second join here would race it and read 255)."""
    job = client.app.state.jobs._jobs[job_id]
    end = time.monotonic() + seconds
    while job.finished is None and time.monotonic() < end:
        time.sleep(0.05)
    assert job.finished is not None, "the job's reader thread never saw the process end"
    assert not job.process.is_alive()
    return job.exitcode


def _wait(client, job_id, states=("done", "failed", "cancelled"), polls=1200, until=None):
    """The job's status once it is in one of ``states`` (or ``until(status)`` holds), polled every 50 ms."""
    for _ in range(polls):
        s = client.get(f"/api/jobs/{job_id}").json()
        if s["state"] in states or (until is not None and until(s)):
            return s
        time.sleep(0.05)
    raise AssertionError(f"job {job_id} still {s['state']}: {s['progress'][-1:]}")


def test_a_report_check_job_marks_the_right_and_the_wrong_line(client):
    report = ("# Planar arm\n\n| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |\n|---|---|---|---|---|\n"
              "| 1 | $L_1$ | 0 | 0 | $\\theta_1$ |\n| 2 | $L_2$ | 0 | 0 | $\\theta_2$ |\n\n"
              "$$x = L_1 c_1 + L_2 c_{12}$$\n\n$$y = L_1 s_1$$\n")  # x right; y misses L_2 s_12 (Spong eq. 3.13)
    job = client.post("/api/jobs", json={"kind": "check", "payload": {"text": report, "kind": "md"}}).json()
    s = _wait(client, job["id"])
    assert s["state"] == "done", s
    res = s["result"]
    assert res["summary"]["correct"] == 1 and res["summary"]["incorrect"] == 1
    assert [(c["line"], c["verdict"]) for c in res["claims"]] == [(8, "correct"), (10, "incorrect")]
    assert "<html" in res["html"].lower() and "incorrect" in res["html"]


def test_a_long_job_is_cancelled_and_never_blocks_the_quick_answers(client):
    """A full report of a 7-joint arm (symbolic dynamics: minutes) runs in its own process: while it runs, quick
    answers come back; cancel ends its process."""
    panda = client.post("/api/catalogue/load", json={"name": "panda"}).json()["robot"]
    job = client.post("/api/jobs", json={"kind": "report", "payload": {"robot": panda}}).json()
    assert job["state"] == "running"
    for k in range(20):
        r = client.post("/api/kinematics", json={"robot": panda, "q": [0.1 * k] * 7})
        assert r.status_code == 200
    assert client.get(f"/api/jobs/{job['id']}").json()["state"] == "running"  # 20 answers while it worked
    assert client.post(f"/api/jobs/{job['id']}/cancel").json()["state"] == "cancelled"
    assert _exit_code(client, job["id"]) == -signal.SIGTERM
    assert _wait(client, job["id"])["state"] == "cancelled"
    _one_line_error(client.get("/api/jobs/no-such-job"), 404)


def test_a_reachability_job_reports_its_progress_and_cancel_ends_its_process(client):
    """The reachability map of puma560 at 5 cm (a minute or more of work): its progress is the library's progress
    line (a percentage of samples, then of voxels); cancel ends the job's process.  A bad voxel size is one line."""
    puma = client.post("/api/catalogue/load", json={"name": "puma560"}).json()["robot"]
    job = client.post("/api/jobs", json={"kind": "reachability",
                                         "payload": {"robot": puma, "resolution": 0.05, "orientations": 100}}).json()
    s = _wait(client, job["id"], until=lambda st: any("%" in line for line in st["progress"]))
    assert s["state"] == "running", s
    line = next(x for x in s["progress"] if "%" in x)
    assert line.split("%")[0].replace(".", "").strip().isdigit() and ("samples" in line or "voxels" in line)
    assert client.post(f"/api/jobs/{job['id']}/cancel").json()["state"] == "cancelled"
    assert _exit_code(client, job["id"]) == -signal.SIGTERM
    for bad in (0.001, "0.1", True):
        r = client.post("/api/jobs", json={"kind": "reachability", "payload": {"robot": puma, "resolution": bad}})
        s = _wait(client, r.json()["id"])
        assert s["state"] == "failed" and "'resolution'" in s["error"] and "\n" not in s["error"]


def test_a_workspace_of_a_hundred_million_samples_reports_its_progress_and_is_cancelled(client):
    """The issue's long work: puma560's workspace at 10⁸ samples streams through the library's sampler with its
    progress line (a percentage of the samples) as the job's progress; cancel ends the process."""
    puma = client.post("/api/catalogue/load", json={"name": "puma560"}).json()["robot"]
    job = client.post("/api/jobs", json={"kind": "workspace", "payload": {"robot": puma, "samples": 10**8}}).json()
    s = _wait(client, job["id"], until=lambda st: any("%" in line for line in st["progress"]))
    assert s["state"] == "running", s
    assert any(x.endswith("samples") or "samples " in x for x in s["progress"] if "%" in x)
    assert client.post(f"/api/jobs/{job['id']}/cancel").json()["state"] == "cancelled"
    assert _exit_code(client, job["id"]) == -signal.SIGTERM


def test_a_job_in_the_same_slot_supersedes_the_running_one_and_never_counts_against_the_limit(client):
    """A page's panel names its slot: the next job there cancels the running one in the same step (the page's own
    cancel may arrive late on a busy machine), so a panel restarted more often than MAX_RUNNING never gets a 429;
    another slot's job is left alone."""
    panda = client.post("/api/catalogue/load", json={"name": "panda"}).json()["robot"]
    start = lambda slot: client.post("/api/jobs", json={"kind": "report", "payload": {"robot": panda}, "slot": slot})
    other = start("page:other").json()
    firsts = [start("page:report").json() for _ in range(MAX_RUNNING + 1)]
    assert all(j["state"] == "running" for j in firsts)  # no 429, though MAX_RUNNING + 2 were started
    jobs = client.app.state.jobs._jobs
    assert [jobs[j["id"]].state for j in firsts] == ["cancelled"] * MAX_RUNNING + ["running"]
    assert jobs[other["id"]].state == "running"
    for j in firsts + [other]:
        client.post(f"/api/jobs/{j['id']}/cancel")
    for j in firsts + [other]:
        assert _exit_code(client, j["id"]) == -signal.SIGTERM
    _one_line_error(start("x" * 65), 422)
    _one_line_error(start(7), 422)


def test_a_report_job_reads_a_typed_q_exactly_and_takes_the_rates_and_the_wrench(client):
    payload = {"robot": PLANAR, "q": "pi/4, -pi/3", "qd": "0.1, 0.2", "wrench": "10, 0, -5, 0, 0, 1",
               "topics": ["case", "statics"]}
    s = _wait(client, client.post("/api/jobs", json={"kind": "report", "payload": payload}).json()["id"])
    assert s["state"] == "done", s
    res = s["result"]
    assert [x["key"] for x in res["sections"]] == ["case", "statics"] and all(x["status"] == "done" for x in res["sections"])
    # A_1 at q1 = π/4 exactly: cos = sin = √2/2 (not 0.7071); the wrench is the typed one
    assert "A_{1} = \\begin{bmatrix}\\frac{\\sqrt{2}}{2} & - \\frac{\\sqrt{2}}{2}" in res["md"]
    assert "F = (10, 0, -5, 0, 0, 1)" in res["md"] and "<section" in res["html"] and "\\begin" in res["tex"]


def test_a_pdf_report_when_a_latex_engine_is_there(client):
    from denavit.report import latex_engine

    payload = {"robot": PLANAR, "topics": ["model"], "pdf": True}
    res = _wait(client, client.post("/api/jobs", json={"kind": "report", "payload": payload}).json()["id"])["result"]
    import base64

    if latex_engine() is None:
        assert res["pdf"] == "" and "no LaTeX engine" in res["pdf_note"]
    else:
        assert base64.b64decode(res["pdf"])[:5] == b"%PDF-" and res["pdf_note"] == ""


def test_a_claims_file_is_judged_claim_by_claim(client):
    """planar2r (L1 = L2 = 1): at q = 0 the end effector is at x = 2, stretched along x; at q = (π/2, 0) at y = 2."""
    claims = ("claims:\n  - id: stretched\n    quantity: position\n    q: '0, 0'\n    value: [2, 0, 0]\n"
              "  - id: wrong\n    quantity: position\n    q: 'pi/2, 0'\n    value: [2, 0, 0]\n")
    doc = client.post("/api/catalogue/load", json={"name": "planar2r"}).json()["robot"]
    payload = {"text": claims, "kind": "yaml", "robot": doc}
    s = _wait(client, client.post("/api/jobs", json={"kind": "check", "payload": payload}).json()["id"])
    assert s["state"] == "done", s
    assert [(c["id"], c["verdict"]) for c in s["result"]["claims"]] == [("stretched", "correct"), ("wrong", "incorrect")]
    assert "tmp" not in s["result"]["text"] and "denavit-web-" not in s["result"]["text"]  # no private path shown
    # each verdict names its claim's lines in the file, so the page marks it in place; "auto" tells a claims file
    # (a top-level claims: key) from a report
    assert [(c["line"], c["end_line"]) for c in s["result"]["claims"]] == [(2, 5), (6, 9)]
    payload["kind"] = "auto"
    s = _wait(client, client.post("/api/jobs", json={"kind": "check", "payload": payload}).json()["id"])
    assert s["result"]["kind"] == "claims" and s["result"]["source"] == claims


def test_claim_lines_follow_the_yaml_layout():
    """The lines of each claim, counted by hand in block, flow and bare-list files."""
    block = "robot: x\nclaims:\n  - id: a\n    value: 1\n\n  # b next\n  - id: b\n    value: |\n      2\n"
    assert claim_lines(block) == [(3, 4), (7, 9)]
    assert claim_lines("claims: [{id: a, value: 1},\n  {id: b, value: 2}]") == [(1, 1), (2, 2)]
    assert claim_lines("- quantity: fk\n  value: 1\n- quantity: fk\n  value: 2") == [(1, 2), (3, 4)]
    assert claim_lines("claims: 3\n") == []


def test_the_formula_job_gives_the_symbolic_pose(client):
    s = _wait(client, client.post("/api/jobs", json={"kind": "formula", "payload": {"robot": PLANAR}}).json()["id"])
    assert s["state"] == "done", s
    maths = " ".join(st["math"] for st in s["result"]["steps"] if "math" in st)
    # p_x = L1 cos q1 + L2 cos(q1 + q2) for the planar elbow arm (Spong 2006 eq. 3.13): both lengths appear
    assert "L_{1}" in maths and "L_{2}" in maths and "T" in maths


def test_serve_without_the_extra_says_what_to_install(monkeypatch, capsys, tmp_path):
    """One line naming the extra, and the exit code of every command's missing extra (1, as ``plot`` without
    matplotlib: docs/pictures.md), not the 2 of bad input."""
    monkeypatch.setitem(sys.modules, "starlette", None)
    assert main(["serve", "planar2r"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'pip install "denavit[web]"' in err[0] and err[0].startswith("denavit serve: ")
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert main(["plot", "planar2r", "-q", "0, 0", "-o", str(tmp_path / "arm.png")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install 'denavit[plot]'" in err[0]


def test_serve_on_a_port_in_use_is_one_line(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        assert main(["serve", "planar2r", "--port", str(port)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"port {port}" in err[0] and "in use" in err[0]


def test_serve_prints_its_address_warns_off_loopback_and_answers():
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "denavit", "serve", "planar2r", "--port", "0", "--host", "127.0.0.2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = proc.stdout.readline()
        assert line.startswith("denavit workbench at http://127.0.0.2:"), line
        url = line.split()[3]
        page = urllib.request.urlopen(url, timeout=60).read().decode()
        assert "planar2r" in page and "/static/workbench.js" in page
        names = json.loads(urllib.request.urlopen(url + "api/catalogue", timeout=60).read())["names"]
        assert "puma560" in names
    finally:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    assert proc.returncode in (0, 130)  # Ctrl-C: the command line's 130 when uvicorn passes the signal on
    assert "warning: listening on 127.0.0.2" in err.splitlines()[0] and "Traceback" not in err
