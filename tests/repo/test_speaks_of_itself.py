"""The repository speaks only of capsflow: what the code does, why, and the measurement with the
command that reproduces it. Words about the process that built it — work sessions, issue numbers,
"earlier notes" — belong to git log, not to code, comments, docs, scripts or test names."""
import re

from repo_files import ROOT, text_of, tracked_files

# Each pattern with why it is refused. Case-insensitive, on whole words.
FORBIDDEN = [
    (re.compile(r"\bsessions?\b", re.I), "a work session of the project's process"),
    (re.compile(r"(?<![a-z0-9])s\d{2}p?_", re.I), "a session tag in a name (s28_, s29p_)"),
    (re.compile(r"\bissues?\s*#?\d+", re.I), "an issue number"),
    (re.compile(r"\bitem\s+\d+\s+of\s+(the\s+)?issue", re.I), "an issue's item"),
    (re.compile(r"\bearlier\s+(design\s+)?notes\b", re.I), "earlier notes"),
]


def offending_lines():
    found = []
    for path in tracked_files():
        rel = path.relative_to(ROOT).as_posix()
        if rel == "tests/repo/test_speaks_of_itself.py":  # the patterns themselves
            continue
        text = text_of(path)
        if text is None:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for pattern, why in FORBIDDEN:
                if pattern.search(line):
                    found.append(f"{rel}:{number}: {why}: {line.strip()[:120]}")
    return found


def test_no_words_about_the_process():
    found = offending_lines()
    assert not found, f"{len(found)} lines speak of the process, not of capsflow:\n" + "\n".join(found[:60])


def test_the_patterns_catch_what_they_are_for():
    # The check must be able to fail: each pattern matches its example and not a near miss.
    examples = {0: ("measured in session 12", "in possession of"), 1: ("perf/stress/auto_s29_x", "as29_"),
                2: ("fixed in issue 27", "an issue with the mesh"), 3: ("item 3 of the issue", "item 3 of the list"),
                4: ("to match earlier design notes", "earlier measurements")}
    for k, (bad, good) in examples.items():
        pattern = FORBIDDEN[k][0]
        assert pattern.search(bad), (k, bad)
        assert not pattern.search(good), (k, good)
