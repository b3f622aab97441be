"""Every reference from one file to a numbered section of a doc ("perf/RESULTS.md §2.4",
"docs/time-integration.md §5.12") names a section that exists: renumbering a doc must carry its
readers along. A single number is a chapter ("docs/time-integration.md §5": its sections are 5.x)."""
import re

from repo_files import ROOT, text_of, tracked_files

REFERENCE = re.compile(r"((?:perf/RESULTS|docs/[a-z0-9\-]+)\.md)`?\)?\s*§\s*(\d+(?:\.\d+)*)")
HEADING = re.compile(r"#+\s+(\d+(?:\.\d+)*)\b")


def sections_of(path):
    numbers = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        m = HEADING.match(line)
        if m:
            numbers.add(m.group(1))
    chapters = {n.split(".")[0] for n in numbers}
    return numbers | chapters


def test_every_section_reference_names_a_section_that_exists():
    known, missing = {}, []
    for path in tracked_files():
        text = text_of(path)
        if text is None:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for m in REFERENCE.finditer(line):
                doc, section = m.group(1), m.group(2)
                target = ROOT / doc
                if doc not in known:
                    known[doc] = sections_of(target) if target.is_file() else None
                if known[doc] is None or section not in known[doc]:
                    missing.append(f"{path.relative_to(ROOT).as_posix()}:{number}: {doc} §{section}")
    assert not missing, "references to sections that do not exist:\n" + "\n".join(missing)
