"""Packaging: public names resolve, the core import stays light, every catalogue robot loads."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

import denavit


def test_every_public_name_resolves():
    for name in denavit.__all__:
        assert getattr(denavit, name) is not None, name
    import denavit.numeric as numeric
    import denavit.symbolic as symbolic

    for mod in (numeric, symbolic):
        for name in mod.__all__:
            assert getattr(mod, name) is not None, f"{mod.__name__}.{name}"


def test_import_denavit_loads_neither_sympy_nor_matplotlib():
    code = "import sys, denavit; import denavit.numeric; print('sympy' in sys.modules, 'matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_catalogue_robots_all_load_with_sources():
    names = denavit.catalogue_names()
    assert len(names) >= 15
    for name in names:
        robot = denavit.load_robot(name)
        assert robot.dof >= 1
        assert robot.source == f"catalogue:{name}"


def test_catalogue_files_cite_a_source():
    from importlib import resources

    for name in denavit.catalogue_names():
        text = (resources.files("denavit") / "data" / "robots" / f"{name}.yaml").read_text()
        assert text.lstrip().startswith("# Source:"), name


def test_public_names_load_on_first_use_and_match_what_type_checkers_see():
    """``denavit/__init__`` imports its public names on first use (PEP 562).  Its ``TYPE_CHECKING`` imports (what
    mypy and editors read) name the same modules and names as the lazy table, and ``__all__`` is exactly those
    plus the eager ones; a fresh ``import denavit`` loads none of the heavy subpackages, and each resolves when
    named (as a name or as ``denavit.<submodule>``)."""
    import ast
    from pathlib import Path

    tree = ast.parse(Path(denavit.__file__).read_text(encoding="utf-8"))
    guarded = next(n for n in tree.body if isinstance(n, ast.If) and ast.unparse(n.test) == "TYPE_CHECKING")
    seen = {}
    for node in guarded.body:
        assert isinstance(node, ast.ImportFrom) and node.level == 1
        seen.setdefault(node.module, []).extend(a.name for a in node.names)
    assert {m: sorted(v) for m, v in seen.items()} == {m: sorted(v) for m, v in denavit._LAZY.items()}
    eager = {"DenavitError", "DenavitWarning", "MissingDependencyError", "ModelError", "ParseError", "ShapeError",
             "UnsupportedRobotError", "Convention", "DHLink", "DHRobot", "Frame", "JointType", "LinkInertia"}
    lazy = {n for names in denavit._LAZY.values() for n in names}
    assert set(denavit.__all__) == eager | lazy | {"__version__"} and len(denavit.__all__) == len(set(denavit.__all__))
    assert lazy <= set(dir(denavit))

    code = ("import sys, denavit; heavy = ['denavit.ik', 'denavit.codegen', 'denavit.interop', 'denavit.calibration',"
            " 'denavit.numeric', 'numba', 'scipy']; print([m for m in heavy if m in sys.modules]);"
            " print(denavit.numeric.rnea is denavit.rnea, denavit.ik.analytic_ik is denavit.analytic_ik);"
            " print('denavit.ik' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[:3] == ["[]", "True True", "True"]
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        denavit.not_a_name  # noqa: B018
    with pytest.raises(AttributeError):
        denavit.__not_a_dunder__  # noqa: B018


#: What the command line's parser, ``--help`` and the commands that only read a robot must not load.
CLI_HEAVY = ("denavit.scale", "denavit.numeric", "numba", "sympy", "matplotlib")


def _modules_loaded_by(argv: list[str], probe: str = "denavit.scale") -> dict:
    """In a fresh interpreter: build the parser, run ``main(argv)``; the heavy modules then loaded, the exit code,
    the output, and whether the same check sees ``probe`` once it is imported (so an empty list means something)."""
    code = ("import contextlib, io, json, sys; import denavit.cli as cli; cli.build_parser(); out = io.StringIO()\n"
            f"with contextlib.redirect_stdout(out): rc = cli.main({argv!r})\n"
            f"heavy = {CLI_HEAVY!r}; loaded = [m for m in heavy if m in sys.modules]; import {probe}\n"
            "print(json.dumps({'rc': rc, 'loaded': loaded, 'probe': [m for m in heavy if m in sys.modules],"
            " 'out': out.getvalue()}))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


@pytest.mark.parametrize("argv", [["--help"], ["workspace", "--help"], ["reachability", "--help"],
                                  ["jacobian", "--help"], ["robots"], ["show", "puma560"]])
def test_cli_parser_help_and_show_load_neither_scale_nor_numeric(argv):
    """Building the parser and ``denavit --help`` (and each subcommand's), ``robots`` and ``show`` import neither
    :mod:`denavit.scale` nor :mod:`denavit.numeric`, numba, sympy or matplotlib: the defaults and limits the help
    texts show come from ``denavit._constants``; the commands import what they use when they run."""
    got = _modules_loaded_by(argv)
    assert got["rc"] == 0 and got["out"]
    assert got["loaded"] == []
    assert "denavit.scale" in got["probe"]  # the check sees a loaded module
    if argv[0] == "workspace":  # the limits shown are the library's
        from denavit.scale import MAX_SAMPLES

        assert f"{MAX_SAMPLES:.0e}" in " ".join(got["out"].split())
    if argv[0] == "reachability":
        from denavit.scale import DEFAULT_ORIENTATIONS, MAX_ORIENTATIONS

        assert f"(default {DEFAULT_ORIENTATIONS}; at most {MAX_ORIENTATIONS})" in " ".join(got["out"].split())


def test_console_help_imports_neither_scale_nor_numeric():
    """``python -m denavit --help`` as a user runs it (``__main__``, then exit): the modules loaded at exit."""
    code = (f"import atexit, sys; heavy = {CLI_HEAVY!r}\n"
            "atexit.register(lambda: print([m for m in heavy if m in sys.modules], 'denavit.cli._scale' in sys.modules,"
            " file=sys.stderr))\n"
            "import runpy; sys.argv = ['denavit', '--help']; runpy.run_module('denavit', run_name='__main__')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0 and done.stdout.startswith("usage: denavit")
    assert done.stderr.strip() == "[] True"  # nothing heavy, though every subcommand's module was loaded


def test_cli_check_report_does_not_load_the_scale_package():
    """``denavit check REPORT`` judges with the engines it needs (sympy, numeric) but not :mod:`denavit.scale`."""
    report = Path(__file__).parent.parent / "examples" / "reports" / "planar2r-homework.md"
    got = _modules_loaded_by(["check", str(report)], probe="denavit.scale")
    assert got["rc"] == 0 and got["out"]
    assert "denavit.scale" not in got["loaded"] and "matplotlib" not in got["loaded"]
    assert "denavit.scale" in got["probe"]
