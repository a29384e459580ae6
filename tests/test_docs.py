"""The README and docs/*.md run: every ```python block, every `denavit ...` line of a ```bash / ```console block.

- Python: the blocks of one file run in order in one fresh namespace (so a later block may use an earlier
  block's names; a ``print(...)  # -> text`` line must print that text), in a temporary working directory
  holding a copy of ``examples/`` (the files the docs' commands use, ``examples/my_arm.yaml``,
  ``examples/table.txt``, …, are shipped there), with matplotlib's Agg backend.
- Shell: each line starting with ``denavit `` (after an optional ``$ `` prompt) runs through
  ``denavit.cli.main`` in-process in such a directory; it must exit 0.  Other lines (``pip install``,
  ``python -m pytest``, …) are not run.  In a ```console block, the lines under a ``$`` command up to the next
  ``$`` are the output shown in the docs and must appear, line by line (spaces normalised), in the output
  (a line ``...`` stands for lines left out).
- A block is skipped only with a marker on the line before it: ``<!-- skip-test: the reason -->``.  A block
  preceded by ``<!-- slow -->`` runs under the ``slow`` marker; ``SLOW_COMMANDS`` lists shell lines that are
  slow (symbolic 6-DOF work, big reports).
- Fences without a language (command synopses with ``[options]``, error messages, output) and data blocks
  (```yaml, ```json) are text, not run; yaml blocks that are whole robot files are loaded (``load_robot``).
- What the prose names must exist: a module or attribute of denavit (``denavit.x.y``, ``cli._common.MAX_VALUE``,
  outside code blocks), and the target of a relative link (the file, and the heading an ``#anchor`` points to).
- README.md's figures (test counts, times) stand only in the block scripts/readme_figures.py writes.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import shutil
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC_FILES = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))

#: Shipped files copied into the working directory under the names the docs use.
COPIES = {"examples": "examples"}

#: Shell lines (prefixes) that take more than a few seconds: run only in the full suite.
SLOW_COMMANDS = (
    "denavit report ",
    "denavit dynamics puma560 --symbolic",
    "denavit ik puma560 --derive",
    "denavit animate ",
    "denavit workspace ",
)
#: Files whose python blocks take more than a few seconds together (the reason), run only in the full suite.
SLOW_PYTHON = {"docs/pictures.md": "an animated GIF and a 100 000-sample workspace (~25 s on CI)",
               "docs/report.md": "a full Puma 560 derivation and its HTML (~6 s)"}


@dataclass
class Block:
    path: Path
    line: int  # 1-based line of the opening fence
    lang: str
    text: str
    skip: str | None  # the reason, when marked skip-test
    slow: bool


_FENCE = re.compile(r"^(\s*)```\s*([A-Za-z0-9_+-]*)\s*$")
_SKIP = re.compile(r"<!--\s*skip-test\s*(?::\s*(.*?))?\s*-->")
_SLOW = re.compile(r"<!--\s*slow\s*-->")


def doc_blocks(path: Path) -> list[Block]:
    """Fenced code blocks of a Markdown file, with the marker comment of the line before each."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, lang = len(m.group(1)), m.group(2).lower()
        prev = next((lines[k] for k in range(i - 1, -1, -1) if lines[k].strip()), "")
        j = i + 1
        while j < len(lines) and not _FENCE.match(lines[j]):
            j += 1
        body = "\n".join(line[indent:] for line in lines[i + 1:j])
        skip = _SKIP.search(prev)
        out.append(Block(path, i + 1, lang, body, (skip.group(1) or "no reason given") if skip else None,
                         bool(_SLOW.search(prev))))
        i = j + 1
    return out


def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def _workdir(tmp_path: Path) -> Path:
    for name, src in COPIES.items():
        s = ROOT / src
        if s.is_dir():
            shutil.copytree(s, tmp_path / name)
        else:
            shutil.copy(s, tmp_path / name)
    return tmp_path


# ---------------------------------------------------------------------------------------------------------
# python blocks

_PRINTS = re.compile(r"^\s*print\(.*\)\s*#\s*(?:->|→)\s*(.+?)\s*$", re.M)


def _python_cases():
    cases = []
    for path in DOC_FILES:
        blocks = [b for b in doc_blocks(path) if b.lang in ("python", "py", "pycon")]
        if blocks:
            slow = _rel(path) in SLOW_PYTHON or any(b.slow for b in blocks if not b.skip)
            marks = [pytest.mark.slow] if slow else []
            cases.append(pytest.param(path, blocks, id=_rel(path), marks=marks))
    return cases


@pytest.mark.parametrize(("path", "blocks"), _python_cases())
def test_python_blocks_run(path, blocks, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(_workdir(tmp_path))
    namespace: dict = {"__name__": f"docs:{_rel(path)}"}
    ran = 0
    for b in blocks:
        if b.skip:
            continue
        code = compile(b.text, f"{_rel(path)}:{b.line}", "exec")  # tracebacks name the doc file and line
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(code, namespace)  # noqa: S102 - the project's own documentation, not user input
        printed = [_norm(line) for line in out.getvalue().splitlines()]
        for shown in _PRINTS.findall(b.text):  # print(...)  # -> what the docs say it prints
            assert _norm(shown) in printed, f"{_rel(path)}:{b.line}: the docs show {shown!r}, printed {printed}"
        ran += 1
    assert ran > 0


# ---------------------------------------------------------------------------------------------------------
# shell lines

@dataclass
class Command:
    block: Block
    line: str
    expected: list[str]  # output lines the docs show under the command (console blocks)


def shell_commands(block: Block) -> list[Command]:
    cmds: list[Command] = []
    current = None
    for raw in block.text.splitlines():
        line = raw.rstrip()
        prompt = line.startswith("$ ")
        if prompt:
            line = line[2:]
        if block.lang == "console" and not prompt:
            if current is not None and line.strip():
                current.expected.append(line)
            continue
        current = None
        if line.startswith("denavit "):
            current = Command(block, line, [])
            cmds.append(current)
    return cmds


def _shell_cases():
    cases = []
    for path in DOC_FILES:
        for b in doc_blocks(path):
            if b.lang not in ("bash", "sh", "shell", "console") or b.skip:
                continue
            for c in shell_commands(b):
                slow = b.slow or c.line.startswith(SLOW_COMMANDS)
                ident = f"{_rel(path)}:{b.line}:{c.line[8:48]}"
                cases.append(pytest.param(c, id=ident, marks=[pytest.mark.slow] if slow else []))
    return cases


def _norm(s: str) -> str:
    return " ".join(s.split())


@pytest.mark.parametrize("cmd", _shell_cases())
def test_shell_commands_run(cmd, tmp_path, monkeypatch):
    from denavit.cli import main

    if any(w in cmd.line for w in ("plot ", "animate ", "workspace ", "report ")):
        pytest.importorskip("matplotlib")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(_workdir(tmp_path))
    argv = shlex.split(cmd.line, comments=True)
    assert argv[0] == "denavit"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv[1:])
    assert code == 0, f"{cmd.line!r} exited {code}: {err.getvalue().strip()[:500]}"
    shown = [_norm(line) for line in out.getvalue().splitlines()]
    for line in cmd.expected:
        if line.strip() in ("...", "…"):  # the docs leave out the rest of the output
            continue
        assert _norm(line) in shown, f"{cmd.line!r}: the docs show {line!r}, the command did not print it"


# ---------------------------------------------------------------------------------------------------------
# the harness itself, and robot files shown in full

def test_every_doc_has_been_parsed_and_markers_give_reasons():
    seen = 0
    for path in DOC_FILES:
        for b in doc_blocks(path):
            seen += 1
            assert b.skip != "no reason given", f"{_rel(path)}:{b.line}: <!-- skip-test: say why -->"
    assert seen > 10


def test_console_blocks_pair_output_with_their_command():
    b = Block(Path("x.md"), 1, "console", "$ denavit robots --json  # all\n{\"a\": 1}\n\n$ echo hi\nhi\n", None, False)
    (c,) = shell_commands(b)
    assert c.line == "denavit robots --json  # all" and c.expected == ['{"a": 1}']
    assert shlex.split(c.line, comments=True) == ["denavit", "robots", "--json"]


def _robot_yaml_cases():
    cases = []
    for path in DOC_FILES:
        for b in doc_blocks(path):
            if b.lang in ("yaml", "yml") and not b.skip and re.search(r"^joints:", b.text, re.M) \
                    and re.search(r"^convention:", b.text, re.M):
                cases.append(pytest.param(b, id=f"{_rel(path)}:{b.line}"))
    return cases


@pytest.mark.parametrize("block", _robot_yaml_cases())
def test_robot_files_shown_in_the_docs_load(block, tmp_path):
    import denavit

    f = tmp_path / "shown.yaml"
    f.write_text(block.text, encoding="utf-8")
    robot = denavit.load_robot(str(f))
    import numpy as np

    T = denavit.forward_kinematics(robot, np.zeros(robot.dof))
    assert robot.dof > 0 and T.shape == (4, 4) and np.all(np.isfinite(T))


# ---------------------------------------------------------------------------------------------------------
# what the prose names: modules and attributes of denavit, relative links

_SRC = ROOT / "src" / "denavit"
#: denavit's top-level modules and subpackages: a dotted name starting with one of them (or with ``denavit``)
#: is a name in denavit (``cli._common.MAX_VALUE``, ``denavit.symbolic.forward_kinematics_sym``).
_MODULES = sorted({p.stem if p.is_file() else p.name for p in _SRC.iterdir()
                   if (p.suffix == ".py" or (p / "__init__.py").is_file()) and not p.name.startswith("__")})
_NAME = re.compile(r"(?<![\w./-])((?:denavit|" + "|".join(map(re.escape, _MODULES)) + r")(?:\.[A-Za-z_]\w*)+)(?![\w/-])")
_FILE_NAME = re.compile(r"\.(?:html?|md|tex|pdf|ya?ml|png|py|json|csv|npz|txt|urdf|xml|gif|mp4|svg|toml|c|h|js)$")
#: Dotted names in the docs that are not denavit's, each with whose they are.
FOREIGN_NAMES = {"model.armature": "Pinocchio's Model (docs/interop.md, docs/dynamics.md)"}
_LINK = re.compile(r"\[[^\]\n]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def _prose(text: str) -> str:
    """The Markdown text without its fenced code blocks (their names are checked by running them)."""
    return re.sub(r"^\s*```.*?^\s*```", "", text, flags=re.S | re.M)


def denavit_names(text: str) -> list[str]:
    """Dotted names of denavit's modules and attributes in ``text``'s prose (file names left out)."""
    return [n for n in _NAME.findall(_prose(text)) if not _FILE_NAME.search(n) and n not in FOREIGN_NAMES]


def name_exists(name: str) -> bool:
    """``name`` (``denavit.`` implied) is an importable module or an attribute reached from one."""
    import importlib
    import types

    parts = name.split(".")
    parts = parts[1:] if parts[0] == "denavit" else parts
    obj, module = importlib.import_module("denavit"), "denavit"
    for part in parts:
        if hasattr(obj, part):
            obj = getattr(obj, part)
            module = obj.__name__ if isinstance(obj, types.ModuleType) else None
            continue
        if module is None:  # an attribute of an object that has no such attribute
            return False
        try:
            obj = importlib.import_module(f"{module}.{part}")
        except ImportError:
            return False
        module = obj.__name__
    return True


def heading_anchors(path: Path) -> set[str]:
    """GitHub's anchors of a Markdown file's headings (lower case, punctuation dropped, spaces to ``-``,
    repeats numbered ``-1``, ``-2``), plus explicit ``<a id=...>`` / ``<a name=...>``."""
    text = path.read_text(encoding="utf-8")
    out: set[str] = set()
    for line in _prose(text).splitlines():
        m = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m:
            slug = base = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
            k = 1
            while slug in out:
                slug, k = f"{base}-{k}", k + 1
            out.add(slug)
    return out | set(re.findall(r'<a\s+(?:id|name)="([^"]+)"', text))


def dangling_links(path: Path, text: str) -> list[str]:
    """Relative links of ``text`` (the Markdown file at ``path``) whose file, or heading, does not exist."""
    bad = []
    for target in _LINK.findall(_prose(text)):
        if re.match(r"[A-Za-z][A-Za-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        file, _, anchor = target.partition("#")
        dest = (path.parent / file) if file else path
        if not dest.exists() or (anchor and dest.suffix == ".md" and anchor not in heading_anchors(dest)):
            bad.append(target)
    return bad


@pytest.mark.parametrize("path", DOC_FILES, ids=_rel)
def test_names_of_denavit_in_the_docs_exist(path):
    names = denavit_names(path.read_text(encoding="utf-8"))
    missing = sorted({n for n in names if not name_exists(n)})
    assert not missing, f"{_rel(path)} names what denavit does not have: {missing}"


@pytest.mark.parametrize("path", DOC_FILES, ids=_rel)
def test_relative_links_in_the_docs_reach_their_target(path):
    bad = dangling_links(path, path.read_text(encoding="utf-8"))
    assert not bad, f"{_rel(path)}: links to a missing file or heading: {bad}"


def test_the_name_and_link_checks_catch_a_dangling_one():
    text = ("Use `cli._viz.SAMPLES_RANGE` and `denavit.symbolic.no_such_thing` (not `cli._common.MAX_VALUE`, "
            "`denavit.symbolic.forward_kinematics_sym`, `report.html`).\n\n"
            "See [robot files](robot-file.md#limits), [gone](no-such-page.md), [bad](robot-file.md#no-such-heading)."
            "\n```python\ndenavit.not_checked_in_code\n```\n")
    names = denavit_names(text)
    assert names == ["cli._viz.SAMPLES_RANGE", "denavit.symbolic.no_such_thing", "cli._common.MAX_VALUE",
                     "denavit.symbolic.forward_kinematics_sym"]
    assert [n for n in names if not name_exists(n)] == ["cli._viz.SAMPLES_RANGE", "denavit.symbolic.no_such_thing"]
    assert dangling_links(ROOT / "docs" / "x.md", text) == ["no-such-page.md", "robot-file.md#no-such-heading"]


# ---------------------------------------------------------------------------------------------------------
# README.md's figures

_FIGURE = re.compile(r"\d[\d,.]*\s*(?:k\s+)?(?:tests?|ms|s|seconds?|min|minutes?|hours?|characters)\b"
                     r"|\b(?:a few|about an?|several|half an?|one|two|three|four|five|six|seven|eight|nine|ten|"
                     r"twenty|thirty|in|within|under) (?:seconds?|minutes?|hours?)\b|\ba minute and a half\b", re.I)


def _readme_figures():
    import importlib.util

    spec = importlib.util.spec_from_file_location("readme_figures", ROOT / "scripts" / "readme_figures.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def figures_outside_the_block(readme: str, block: str) -> list[str]:
    return _FIGURE.findall(_prose(readme.replace(block, "")))


def test_readme_figures_stand_only_in_the_block_the_script_writes():
    rf = _readme_figures()
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    block = rf.block_of(readme)
    assert rf.render(rf.parse(block)) == block, "README.md's figures block was edited by hand: run the script"
    assert rf.parse(block)["tests"] > rf.parse(block)["quick"] > 0
    assert figures_outside_the_block(readme, block) == [], "a figure in README.md that no script measures"
    assert rf.report_command(readme)[:2] == ["denavit", "report"]


def test_the_figures_check_catches_a_figure_outside_the_block():
    block = "<!-- figures: begin x -->\n2,860 tests in 90 s\n<!-- figures: end -->"
    text = f"Writes, in a few seconds, a report.\n{block}\nThe suite (3,289 tests, about six minutes).\n"
    assert figures_outside_the_block(text, block) == ["a few seconds", "3,289 tests", "six minutes"]
    assert figures_outside_the_block("The second installs the tests' dependencies (Python ≥ 3.10).", "") == []
