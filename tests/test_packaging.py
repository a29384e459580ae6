"""Packaging: public names resolve, the core import stays light, every catalogue robot loads."""

import subprocess
import sys

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
