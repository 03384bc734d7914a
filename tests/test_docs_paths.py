"""The docs name things that exist: every project path and every dotted project name in backticks
in README.md and docs/*.md, and every relative link with its #anchor, points at something in this
checkout.

Files get moved (issue #24 regrouped ``tracker/`` and ``pipelines/``) and prose keeps the old
names; a reader who follows a path that is not there loses trust in the whole page."""
from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
PROJECT_DIRS = ("tracker/", "gimbal/", "pipelines/", "tests/", "benchmarks/", "samples/", "scripts/", "docs/")

FENCE = re.compile(r"^```.*?^```", re.S | re.M)
SPAN = re.compile(r"`([^`\n]+)`")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^#{1,6}\s+(.+?)\s*$", re.M)
GLOB = re.compile(r"[*?\[]")
DOTTED = re.compile(r"(?:tracker|gimbal|pipelines)(?:\.\w+)+")


def project_paths(text: str) -> list[str]:
    """The words in backticks (outside fenced blocks) that start like a project path, with
    ``path:line``, ``path::name`` and ``#anchor`` suffixes and trailing punctuation taken off."""
    found = []
    for span in SPAN.findall(FENCE.sub("", text)):
        for word in span.split():
            word = word.strip("\"'(),;")
            if not word.startswith(PROJECT_DIRS):
                continue
            word = word.split("::", 1)[0].split("#", 1)[0]
            found.append(re.sub(r":\d+(-\d+)?$", "", word).rstrip(":"))
    return found


def exists(path: str, base: Path = ROOT) -> bool:
    """True when ``path`` (a glob, with ``{a,b}`` alternatives, allowed) names something under ``base``."""
    brace = re.search(r"\{([^{}]*)\}", path)
    if brace:
        return all(exists(path[:brace.start()] + choice + path[brace.end():], base)
                   for choice in brace.group(1).split(","))
    if GLOB.search(path):
        return any(base.glob(path.rstrip("/")))
    return (base / path).exists()


def dotted_names(text: str) -> list[str]:
    """Spans in backticks (outside fenced blocks) that start with a dotted project name, e.g.
    ``tracker.runtime.registry.make_tracker`` or ``pipelines.loop.Loop.step(frame, t)``."""
    return [m.group(0) for span in SPAN.findall(FENCE.sub("", text)) if (m := DOTTED.match(span))]


def resolves(name: str) -> bool | None:
    """True when the longest importable module prefix of ``name`` has the rest as attributes (or
    dataclass fields); None when a module cannot be imported for want of an optional package."""
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        module_name = ".".join(parts[:cut])
        try:
            found: object = importlib.import_module(module_name)
            break
        except ModuleNotFoundError as exc:
            if not (exc.name and name.startswith(exc.name)):
                return None  # the module exists but needs an optional package that is missing
    else:
        return False
    for attribute in parts[cut:]:
        if isinstance(found, type) and attribute in getattr(found, "__dataclass_fields__", {}):
            return True
        if not hasattr(found, attribute):
            return False
        found = getattr(found, attribute)
    return True


def anchors(page: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces to hyphens."""
    return {re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
            for heading in HEADING.findall(FENCE.sub("", page.read_text(encoding="utf-8")))}


def broken_paths(page: Path) -> list[str]:
    return [p for p in project_paths(page.read_text(encoding="utf-8")) if not exists(p)]


def broken_links(page: Path) -> list[str]:
    """Relative links whose file is missing, or whose #anchor is no heading of that file."""
    broken = []
    for target in LINK.findall(FENCE.sub("", page.read_text(encoding="utf-8"))):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto:, ...
            continue
        name, _, anchor = target.partition("#")
        linked = (page.parent / name).resolve() if name else page
        if not linked.exists():
            broken.append(target)
        elif anchor and linked.suffix == ".md" and anchor not in anchors(linked):
            broken.append(target)
    return broken


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_project_path_in_backticks_exists(page: Path) -> None:
    assert broken_paths(page) == []


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_dotted_project_name_in_backticks_resolves(page: Path) -> None:
    assert [n for n in dotted_names(page.read_text(encoding="utf-8")) if resolves(n) is False] == []


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_relative_link_and_anchor_exists(page: Path) -> None:
    assert broken_links(page) == []


def test_a_wrong_path_a_missing_anchor_and_the_suffixes_are_seen(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("# Only heading\n"
                    "`tracker/runtime/subject.py:42`, `tests/tracker/backends/test_dcf.py::test_x[a]`, "
                    "`python benchmarks/bench_*.py --starts`, `tracker/models/nanotrack_v3/`, "
                    "`scripts/{demo,test}.sh`, `out/demo/plot.png`, `tracker.runtime.boxes`\n"
                    "`tracker/subject.py` and `pipelines/virtual_camera.py:10` moved; "
                    "`scripts/{demo,nothing}.sh`\n"
                    "```\npython tracker/nowhere.py\n```\n"
                    "[here](#only-heading) [there](#gone) [file](missing.md)\n", encoding="utf-8")
    assert broken_paths(page) == ["tracker/subject.py", "pipelines/virtual_camera.py", "scripts/{demo,nothing}.sh"]
    assert broken_links(page) == ["#gone", "missing.md"]


def test_a_moved_module_or_a_missing_name_is_seen() -> None:
    text = ("`tracker.runtime.registry.make_tracker`, `pipelines.loop.Loop.step(frame, t)`, "
            "`tracker.runtime.subject.TrackerSettings.track_confidence`, `gimbal.client`, "
            "`tracker.registry.make_tracker`, `pipelines.loop.Loop.nothing`")
    names = dotted_names(text)
    assert [n for n in names if not resolves(n)] == ["tracker.registry.make_tracker", "pipelines.loop.Loop.nothing"]
