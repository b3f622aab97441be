"""The repository's tracked files, for the repo checks (git ls-files; the source tree without git:
every file outside build folders and .git)."""
import os
import pathlib
import subprocess

ROOT = pathlib.Path(os.environ.get("CAPSFLOW_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


def tracked_files():
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], capture_output=True, check=True).stdout
        names = [n for n in out.decode().split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*")
                 if p.is_file() and not any(part.startswith(("build", ".git")) for part in p.relative_to(ROOT).parts)]
    return [ROOT / n for n in names if (ROOT / n).is_file()]


def text_of(path):
    """The file's text, or None for a binary file (a NUL byte in its first 8 kB)."""
    data = path.read_bytes()
    if b"\0" in data[:8192]:
        return None
    return data.decode("utf-8", errors="replace")
