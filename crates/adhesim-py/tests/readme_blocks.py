"""The code blocks of the repository's README.md that a newcomer copies, read from the README
itself so that the tests and .ci/run execute exactly what it prints.

    python3 crates/adhesim-py/tests/readme_blocks.py commands        # the two first commands
    python3 crates/adhesim-py/tests/readme_blocks.py python-install  # the Python install line
    python3 crates/adhesim-py/tests/readme_blocks.py python-example  # the Python example

Each prints the block's text; a README that no longer has the block is an error (exit 1)
naming what was looked for.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[3] / "README.md"

FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.MULTILINE | re.DOTALL)


def blocks(text: str) -> list[tuple[str, str]]:
    """Every fenced block of `text` as (language, body), in order."""
    return [(m.group(1), m.group(2)) for m in FENCE.finditer(text)]


def section(text: str, heading: str) -> str:
    """The text of the `## heading` section, up to the next `## ` heading."""
    start = text.find(f"\n## {heading}\n")
    if start < 0:
        raise LookupError(f"README.md has no section '## {heading}'")
    end = text.find("\n## ", start + 1)
    return text[start : end if end >= 0 else len(text)]


def first_commands(text: str) -> list[str]:
    """The commands of the README's first block (before any heading): one a line."""
    lang, body = blocks(text)[0]
    commands = [line.strip() for line in body.splitlines() if line.strip()]
    if lang or len(commands) != 2:
        raise LookupError(
            "README.md's first block must hold exactly two commands (run, test), "
            f"found {commands!r}"
        )
    return commands


def python_install(text: str) -> str:
    """The install command of the README's Python section, without its comment."""
    for lang, body in blocks(section(text, "Python")):
        if lang == "sh":
            line = body.strip().splitlines()[0]
            return line.split(" #")[0].strip()
    raise LookupError("README.md's '## Python' section has no ```sh install line")


def python_example(text: str) -> str:
    """The first ```python block of the README's Python section."""
    for lang, body in blocks(section(text, "Python")):
        if lang == "python":
            return body
    raise LookupError("README.md's '## Python' section has no ```python block")


def main(argv: list[str]) -> int:
    text = README.read_text(encoding="utf-8")
    what = {
        "commands": lambda: "\n".join(first_commands(text)),
        "python-install": lambda: python_install(text),
        "python-example": lambda: python_example(text).rstrip("\n"),
    }
    if len(argv) != 2 or argv[1] not in what:
        print(f"usage: {argv[0]} {'|'.join(what)}", file=sys.stderr)
        return 2
    try:
        print(what[argv[1]]())
    except LookupError as e:
        print(f"{README}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
