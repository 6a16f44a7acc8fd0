"""Code, docs and tests cite the published works (docs/references.md), never our private text dumps:
no line numbers of the PDF-to-text files ("L1234"), no note files or their sections, no dump file
names. This test greps the repository for those patterns."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ["src", "workflow", "benchmarks", "tests", "config", "docs", "README.md"]
SUFFIXES = {".py", ".smk", ".yaml", ".yml", ".md", ".rst", ".txt", ".toml"}

FORBIDDEN = re.compile(
    r"\bL[0-9]{3,5}\b"  # a line of a text dump: L1234, L2600-2607
    r"|notes/|\bnote 00[0-9]|\bseed 00[0-9]|\.md sec|\bnote'?s? sec\."  # our note files and sections
    r"|_chapters|[0-9]{3}_[0-9a-f]{16}"  # the dumps' directory and file names
    r"|\[[CJ]:[0-9]"  # [C:123] / [J:123], lines of the chapter-6 and journal dumps
)


def _files():
    for entry in SCANNED:
        path = ROOT / entry
        if path.is_file():
            yield path
        elif path.is_dir():
            yield from (p for p in sorted(path.rglob("*")) if p.is_file() and p.suffix in SUFFIXES)


def _offences(text):
    return [f"{n}: {line.strip()}" for n, line in enumerate(text.splitlines(), 1) if FORBIDDEN.search(line)]


def test_the_pattern_catches_dump_references():
    bad = ["(L4339-4342)", "Donev L165-L166", "note 002_ogarko.md sec. 2.2", "seed 003 L1695",
           "seeds/000_chapters/ch04-05.txt", "[C:1008-1010]", "(note sec. 2.7)", "the note's sec. 1.4"]
    good = ["Donev 2006, sec. 4.6.2", "Ogarko 2014, Eq. 3.9", "Torquato & Jiao 2010, Table II",
            "N = 1000 spheres", "Table 4.1", "LLL-reduced", "L2 norm"]
    assert all(_offences(s) for s in bad)
    assert not any(_offences(s) for s in good)


def test_no_references_to_the_text_dumps():
    this = Path(__file__).resolve()
    found = {}
    for path in _files():
        rel = path.relative_to(ROOT).as_posix()
        if path.resolve() == this:
            continue
        offences = _offences(path.read_text(encoding="utf-8", errors="replace"))
        if offences:
            found[rel] = offences
    assert not found, "cite the published works (docs/references.md) instead of:\n" + "\n".join(
        f"{rel}:{line}" for rel, lines in found.items() for line in lines
    )
