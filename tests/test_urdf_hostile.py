"""Hostile URDFs through ``denavit import-urdf``: one clean line naming file and element, exit 2, nothing written.

XML from strangers: entity bombs, external entities, truncated and garbled documents, huge files, deep nesting,
broken trees (missing links, cycles, two parents, branching without --tip), out-of-range and non-numbers,
bodies no rigid body has.  Each case meets the contract of tests/_hostile.py.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from _hostile import assert_accepted_quietly, assert_refused, corpus, run_cli, run_cli_limited

GOOD = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0" rpy="1.5707963 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>
"""


def _swap(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new, 1)


BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE lolz [
 <!ENTITY lol "lol">
 <!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
 <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
 <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
 <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
 <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
 <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<robot name="&lol9;"><link name="a"/></robot>
"""

CASES = {
    "billion laughs": (BILLION_LAUGHS, ["arm.urdf", "DOCTYPE"]),
    "external entity": ("""<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>
<robot name="&x;"><link name="a"/></robot>""", ["arm.urdf", "line 2"]),
    "parameter entity": ("""<!DOCTYPE r [<!ENTITY % p SYSTEM "http://example.com/x.dtd"> %p;]><robot/>""",
                         ["arm.urdf", "refused"]),
    "public DTD": ("""<!DOCTYPE robot PUBLIC "-//x//EN" "http://example.com/robot.dtd"><robot name="a"/>""",
                   ["arm.urdf", "DOCTYPE"]),
    "truncated": (GOOD[: len(GOOD) // 2], ["arm.urdf", "malformed"]),
    "empty": ("", ["arm.urdf"]),
    "binary": ("\x00\x01\x02garbage\xff", ["arm.urdf"]),
    "not a URDF": ("<html><body/></html>", ["arm.urdf", "<html>"]),
    "no links": ("<robot name='x'/>", ["arm.urdf", "no <link>"]),
    "missing link": (_swap('<child link="l2"/>', '<child link="l9"/>'), ["arm.urdf", "l9", "line"]),
    "missing child element": (_swap('<child link="l2"/>', ''), ["arm.urdf", "j2", "child"]),
    "two parents": (_swap("</robot>", '<joint name="j3" type="fixed"><parent link="base"/><child link="l2"/>'
                                      '</joint></robot>'), ["arm.urdf", "j3", "tree"]),
    "cycle": (_swap("</robot>", '<link name="a"/><link name="b"/><joint name="c1" type="fixed"><parent link="a"/>'
                                '<child link="b"/></joint><joint name="c2" type="fixed"><parent link="b"/>'
                                '<child link="a"/></joint></robot>'), ["arm.urdf", "cycle"]),
    "two roots": (_swap("</robot>", '<link name="lonely"/></robot>'), ["arm.urdf", "lonely"]),
    "branching without --tip": (_swap("</robot>", '<link name="cam"/><joint name="jc" type="revolute">'
                                                  '<parent link="l1"/><child link="cam"/></joint></robot>'),
                                ["arm.urdf", "--tip", "cam", "l2"]),
    "huge number": (_swap('xyz="0.2 0 0"', 'xyz="1e300 0 0"'), ["arm.urdf", "j2", "out of range"]),
    "overflow": (_swap('xyz="0.2 0 0"', 'xyz="1e999 0 0"'), ["arm.urdf", "j2", "out of range"]),
    "nan": (_swap('xyz="0.2 0 0"', 'xyz="nan 0 0"'), ["arm.urdf", "j2", "not a number"]),
    "inf": (_swap('<mass value="1"/>', '<mass value="inf"/>'), ["arm.urdf", "mass", "not a number"]),
    "underscore number": (_swap('<mass value="1"/>', '<mass value="1_0"/>'), ["arm.urdf", "not a number"]),
    "two numbers for three": (_swap('xyz="0.2 0 0"', 'xyz="0.2 0"'), ["arm.urdf", "expected 3"]),
    "inertia entry missing": (_swap(' ixy="0" ixz="0" iyz="0"/></inertial></link>\n  <link name="l2">',
                                    ' ixz="0" iyz="0"/></inertial></link>\n  <link name="l2">'),
                              ["arm.urdf", "l1", "ixy"]),
    "negative mass": (_swap('<mass value="1"/>', '<mass value="-1"/>'), ["arm.urdf", "negative"]),
    "zero axis": (_swap('<axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>\n  <joint',
                        '<axis xyz="0 0 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>\n  <joint'),
                  ["arm.urdf", "zero"]),
    "limits reversed": (_swap('lower="-2" upper="2"', 'lower="2" upper="-2"'), ["arm.urdf", "j1", "lower"]),
    "floating joint": (_swap('type="revolute"', 'type="floating"'), ["arm.urdf", "j1", "floating"]),
    "unknown type": (_swap('type="revolute"', 'type="ball"'), ["arm.urdf", "j1", "ball"]),
    "mimic": (_swap('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="j2"/>'), ["arm.urdf", "j1", "mimic"]),
    "duplicate link": (_swap('<link name="base"/>', '<link name="base"/><link name="base"/>'),
                       ["arm.urdf", "base", "already"]),
    "no moving joint": (GOOD.replace('type="revolute"', 'type="fixed"'), ["arm.urdf", "no revolute"]),
    "no joint": ('<robot name="r"><link name="a"/></robot>', ["arm.urdf", "'a'", "has no joints"]),
    "deep nesting": ("<robot>" + "<a>" * 5000 + "</a>" * 5000 + "</robot>", ["arm.urdf", "nested"]),
    "too many elements": ("<robot>" + "<link name='x'/>" * 100_001 + "</robot>", ["arm.urdf", "elements"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_hostile_urdf_refused(case, tmp_path):
    text, mentions = CASES[case]
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path, {"arm.urdf": text})
    assert_refused(o, mentions=mentions)


def test_impossible_inertia_keeps_the_kinematics(tmp_path):
    """A link's tensor breaking the triangle inequality is no longer refused (issue 29): one warning line naming
    the <link> and its line, the kinematics written without inertial data (tests/test_urdf_inertia_gravity.py)."""
    text = _swap('ixx="0.1" iyy="0.1" izz="0.1"', 'ixx="0.1" iyy="0.1" izz="5"')
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path, {"arm.urdf": text})
    assert o.code == 0 and (tmp_path / "arm.yaml").is_file()
    assert o.err.count("\n") == 1 and "<link name='l1'> (line 4)" in o.err and "triangle" in o.err


def test_good_urdf_accepted(tmp_path):
    """The control: the document the cases above break is accepted and written."""
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path, {"arm.urdf": GOOD})
    assert_accepted_quietly(o)
    assert (tmp_path / "arm.yaml").is_file()


@pytest.mark.parametrize("argv, mentions", [
    (["--tip", "nowhere"], ["nowhere", "no such link"]),
    (["--base", "l2", "--tip", "l1"], ["not below"]),
    (["--convention", "craig"], ["convention"]),
    (["--base", "l2"], ["'l2'", "empty", "nearer the root"]),  # was: "no revolute ... between 'l2' and 'l2'"
    (["--base", "l1", "--tip", "l1"], ["'l1'", "empty", "--tip below --base"]),
    (["-o", "arm.png"], ["arm.png"]),
])
def test_bad_options_refused(argv, mentions, tmp_path):
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"] + argv, tmp_path, {"arm.urdf": GOOD})
    assert_refused(o, mentions=mentions)


@pytest.mark.parametrize("name", ["arm.yaml", "arm.TOML", "arm.json"])
def test_a_robot_file_given_as_urdf_says_so(tmp_path, name):
    # was: "malformed XML (not well-formed)" at line 1
    o = run_cli(["import-urdf", name], tmp_path, {name: "name: arm\nconvention: standard\n"})
    assert_refused(o, mentions=[name, "a robot file, not a URDF"])


def test_existing_output_replaced_unless_no_clobber(tmp_path):
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml", "--no-clobber"], tmp_path,
                {"arm.urdf": GOOD, "arm.yaml": "mine\n"})
    assert_refused(o, mentions=["arm.yaml", "--no-clobber"])
    assert (tmp_path / "arm.yaml").read_text() == "mine\n"
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path, {})
    assert o.code == 0, o.err
    import denavit

    assert denavit.load_robot(tmp_path / "arm.yaml").dof > 0


def test_missing_file(tmp_path):
    assert_refused(run_cli(["import-urdf", "nothere.urdf"], tmp_path), mentions=["nothere.urdf"])


def test_hundred_megabyte_file_refused_unread(tmp_path):
    """A sparse 100 MB file: refused by its size, in a child process under a memory limit."""
    path = tmp_path / "big.urdf"
    with open(path, "wb") as fh:
        fh.write(b"<robot>")
        fh.truncate(100 * 1024 * 1024)
    o = run_cli_limited(["import-urdf", "big.urdf", "-o", "big.yaml"], tmp_path, memory_limit=1024**3)
    assert_refused(o, mentions=["big.urdf", "bytes"])


def test_billion_laughs_bounded_in_memory(tmp_path):
    o = run_cli_limited(["import-urdf", "arm.urdf"], tmp_path, {"arm.urdf": BILLION_LAUGHS}, memory_limit=1024**3)
    assert_refused(o, mentions=["arm.urdf"])


@settings(max_examples=corpus(150), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_urdf_refused_cleanly_or_accepted(data, tmp_path):
    """A good URDF cut, spliced and garbled at random: accepted, or refused by the contract; never a crash."""
    text = GOOD
    for _ in range(data.draw(st.integers(1, 3))):
        i = data.draw(st.integers(0, len(text)))
        j = data.draw(st.integers(i, min(len(text), i + 40)))
        text = text[:i] + data.draw(st.sampled_from(["", "<", ">", '"', "&", "&x;", "nan", "-", "1e9", "<a>",
                                                      "</joint>", "\x00", "é", "<!DOCTYPE r>"])) + text[j:]
    folder = Path(tempfile.mkdtemp(dir=tmp_path))
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], folder, {"arm.urdf": text})
    if o.code == 0:
        assert_accepted_quietly(o)
    else:
        assert_refused(o, mentions=["arm.urdf"])


@pytest.mark.parametrize("encoding", ["x-nonexistent", "utf-7", "utf-32", "rot13"])
def test_unknown_xml_encoding_is_one_line(encoding, tmp_path):
    """encoding="x-nonexistent" or "utf-7" in the XML declaration: one line naming it (was an internal error)."""
    text = GOOD.replace('<?xml version="1.0"?>', f'<?xml version="1.0" encoding="{encoding}"?>')
    o = run_cli(["import-urdf", "arm.urdf"], tmp_path, {"arm.urdf": text})
    assert_refused(o, mentions=["arm.urdf", repr(encoding), "UTF-8"])


def test_long_valid_number_is_a_number(tmp_path):
    """A 45-character decimal is a number (was "not a number"): the same arm as with the short one; a number of
    more than MAX_NUMBER_CHARS characters is refused by its length."""
    from denavit.interop import MAX_NUMBER_CHARS, import_urdf

    long = "0.3000000000000000000000000000000000000000001"
    assert len(long) == 45
    (tmp_path / "short.urdf").write_text(GOOD)
    (tmp_path / "long.urdf").write_text(_swap('<origin xyz="0 0 0.3"/>', f'<origin xyz="0 0 {long}"/>'))
    assert import_urdf(str(tmp_path / "long.urdf")).robot.links == import_urdf(str(tmp_path / "short.urdf")).robot.links
    huge = "0." + "3" * MAX_NUMBER_CHARS
    o = run_cli(["import-urdf", "arm.urdf"], tmp_path, {"arm.urdf": _swap('<origin xyz="0 0 0.3"/>',
                                                                          f'<origin xyz="0 0 {huge}"/>')})
    assert_refused(o, mentions=["arm.urdf", f"longer than {MAX_NUMBER_CHARS} characters"])
