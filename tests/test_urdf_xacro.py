"""xacro through the optional xacrodoc: expanded only when asked (xacro evaluates Python expressions), then read
as any URDF; the result equals the import of the same arm written out by hand."""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit.interop import import_urdf

from _hostile import assert_refused, run_cli

XACRO = """<?xml version="1.0"?>
<robot name="two" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="L1" value="0.4"/>
  <xacro:macro name="seg" params="n parent length">
    <link name="l${n}"><inertial><mass value="${n}"/>
      <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="j${n}" type="revolute"><parent link="${parent}"/><child link="l${n}"/>
      <origin xyz="${length} 0 0.1" rpy="${pi/2} 0 0"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  </xacro:macro>
  <link name="base"/>
  <xacro:seg n="1" parent="base" length="0"/>
  <xacro:seg n="2" parent="l1" length="${L1}"/>
</robot>
"""

PLAIN = """<robot name="two"><link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <link name="l2"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.4 0 0.1" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>
</robot>"""


def test_xacro_file_refused_unless_asked(tmp_path):
    o = run_cli(["import-urdf", "arm.urdf.xacro", "-o", "arm.yaml"], tmp_path, {"arm.urdf.xacro": XACRO})
    assert_refused(o, mentions=["arm.urdf.xacro", "--xacro"])


def test_xacro_expanded_equals_the_arm_written_by_hand(tmp_path, rng):
    pytest.importorskip("xacrodoc")
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(XACRO)
    result = import_urdf(path, xacro=True)
    plain = import_urdf(PLAIN)
    assert result.joint_names == ("j1", "j2") and result.cases == plain.cases
    q = rng.uniform(-1, 1, (5, 2))
    np.testing.assert_allclose(denavit.forward_kinematics(result.robot, q), denavit.forward_kinematics(plain.robot, q),
                               atol=1e-15)
    np.testing.assert_allclose(denavit.mass_matrix(result.robot, q), denavit.mass_matrix(plain.robot, q), atol=1e-15)


def test_bad_xacro_is_one_clean_line(tmp_path):
    pytest.importorskip("xacrodoc")
    bad = XACRO.replace('<xacro:seg n="2"', '<xacro:nosuchmacro n="2"')
    o = run_cli(["import-urdf", "arm.xacro", "--xacro", "-o", "arm.yaml"], tmp_path, {"arm.xacro": bad})
    assert_refused(o, mentions=["arm.xacro", "xacro"])


def test_xacro_still_refuses_a_dtd(tmp_path):
    """The document is read as untrusted XML before xacro sees it."""
    bomb = '<!DOCTYPE r [<!ENTITY a "aaaa">]>' + XACRO.split("?>", 1)[1]
    o = run_cli(["import-urdf", "arm.xacro", "--xacro"], tmp_path, {"arm.xacro": bomb})
    assert_refused(o, mentions=["arm.xacro", "DOCTYPE"])


# --- a xacro document is a program: its expansion runs under bounds (issue 29) -------------------------------------

def _program(body: str) -> str:
    return ('<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            f'{body}\n  <link name="base"/>\n</robot>\n')


# 2**40 expansions: hours without a bound
EXPONENTIAL = _program('''  <xacro:macro name="boom" params="n">
    <xacro:if value="${n &lt; 40}"><xacro:boom n="${n+1}"/><xacro:boom n="${n+1}"/></xacro:if>
  </xacro:macro>
  <xacro:boom n="0"/>''')
RECURSIVE = _program('''  <xacro:macro name="loop" params="n"><xacro:loop n="${n+1}"/></xacro:macro>
  <xacro:loop n="0"/>''')


def _children_cpu() -> float:
    import resource

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="RLIMIT_CPU is POSIX")
def test_a_runaway_xacro_macro_is_stopped_by_its_cpu_bound(tmp_path, monkeypatch):
    pytest.importorskip("xacrodoc")
    import denavit.interop._xacro as xacro_module

    monkeypatch.setattr(xacro_module, "XACRO_CPU_SECONDS", 1)
    before = _children_cpu()
    o = run_cli(["import-urdf", "boom.xacro", "--xacro"], tmp_path,
                {"boom.xacro": EXPONENTIAL}, time_limit=120)
    assert_refused(o, mentions=["boom.xacro", "xacro", "CPU"])
    assert _children_cpu() - before < 5  # 1 s of CPU for the expansion (plus the interpreter's start), not hours


def test_a_recursive_xacro_macro_is_one_line(tmp_path):
    pytest.importorskip("xacrodoc")
    o = run_cli(["import-urdf", "loop.xacro", "--xacro"], tmp_path, {"loop.xacro": RECURSIVE})
    assert_refused(o, mentions=["loop.xacro", "xacro"])


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="RLIMIT_AS is POSIX")
def test_a_xacro_expression_asking_for_gigabytes_is_refused_by_the_memory_bound(tmp_path, monkeypatch):
    pytest.importorskip("xacrodoc")
    import denavit.interop._xacro as xacro_module

    monkeypatch.setattr(xacro_module, "XACRO_MEMORY_BYTES", 300 << 20)
    text = _program('''  <xacro:property name="big" value="${'x' * 500000000}"/>\n  <link name="l${big}"/>''')
    o = run_cli(["import-urdf", "big.xacro", "--xacro"], tmp_path, {"big.xacro": text}, time_limit=120)
    assert_refused(o, mentions=["big.xacro", "xacro"])  # 500 MB cannot be had within 300 MB


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="needs a FIFO")
def test_a_xacro_waiting_on_a_fifo_is_stopped_by_the_wall_clock_bound(tmp_path, monkeypatch):
    pytest.importorskip("xacrodoc")
    import os

    import denavit.interop._xacro as xacro_module

    monkeypatch.setattr(xacro_module, "XACRO_WALL_SECONDS", 2)
    os.mkfifo(tmp_path / "pipe.xacro")
    text = _program('  <xacro:include filename="pipe.xacro"/>')
    o = run_cli(["import-urdf", "inc.xacro", "--xacro"], tmp_path, {"inc.xacro": text}, time_limit=120)
    assert_refused(o, mentions=["inc.xacro", "took longer than 2 s"])


def test_the_xacro_bounds_are_public():
    from denavit.interop import XACRO_CPU_SECONDS, XACRO_MEMORY_BYTES, XACRO_WALL_SECONDS

    assert 0 < XACRO_CPU_SECONDS < XACRO_WALL_SECONDS and XACRO_MEMORY_BYTES >= 256 << 20
