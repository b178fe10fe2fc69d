"""The library explains itself from inside the repository: no pointer to a
design document outside it, and no issue numbers (history belongs in git)."""

import re
from pathlib import Path

import spiralid

SOURCES = sorted(Path(spiralid.__file__).parent.rglob("*.py"))
OUTSIDE = re.compile(r"DESIGN\.md|\.\./shared|\bissue \d", re.IGNORECASE)


def test_the_sources_were_found():
    assert len(SOURCES) > 40


def test_no_source_points_outside_the_repository():
    hits = [
        f"{path.name}:{number}: {line.strip()}"
        for path in SOURCES
        for number, line in enumerate(path.read_text().splitlines(), 1)
        if OUTSIDE.search(line)
    ]
    assert not hits
