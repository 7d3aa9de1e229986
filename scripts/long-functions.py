#!/usr/bin/env python3
"""Functions longer than a limit (default 120 lines, from the `fn` line to
its closing brace), outside src/integrate/ (whose steppers follow the
published algorithms line by line) and outside #[cfg(test)] modules.

A long function is a list of steps waiting for names (docs/architecture.md):
split it along them. Exits 1 and lists them when any is found, so it can run
in CI: python3 scripts/long-functions.py [LIMIT]
"""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent / "src"
EXEMPT = ROOT / "integrate"
FN = re.compile(r'\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?(extern\s+"[^"]*"\s+)?fn\s+(\w+)')
TEST_MOD = re.compile(r"\s*(pub(\(.*?\))?\s+)?mod\s")


def code_of(line: str) -> str:
    """The line without comments, strings and character literals."""
    line = re.sub(r"//.*", "", line)
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    return re.sub(r"'(\\.|[^'\\])'", "''", line)


def block_end(lines: list, start: int) -> int:
    """The line closing the block opened at or after `start` (or its `;`)."""
    depth, seen = 0, False
    for j in range(start, len(lines)):
        code = code_of(lines[j])
        for ch in code:
            if ch == "{":
                depth, seen = depth + 1, True
            elif ch == "}":
                depth -= 1
        if seen and depth <= 0:
            return j
        if not seen and code.strip().endswith(";"):
            return j
    return len(lines) - 1


def long_functions(path: Path, limit: int) -> list:
    lines = path.read_text().split("\n")
    skip = set()
    for i, line in enumerate(lines):
        if re.match(r"\s*#\[cfg\(test\)\]", line):
            k = i + 1
            while k < len(lines) and lines[k].strip().startswith("#["):
                k += 1
            if k < len(lines) and TEST_MOD.match(lines[k]):
                skip.update(range(i, block_end(lines, k) + 1))
    found = []
    for i, line in enumerate(lines):
        m = FN.match(line)
        if i in skip or not m:
            continue
        length = block_end(lines, i) - i + 1
        if length > limit:
            found.append((length, path.relative_to(ROOT.parent), i + 1, m.group(7)))
    return found


def main() -> int:
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 120
    found = [
        f
        for path in sorted(ROOT.rglob("*.rs"))
        if EXEMPT not in path.parents
        for f in long_functions(path, limit)
    ]
    for length, path, line, name in sorted(found, reverse=True):
        print(f"{path}:{line}: fn {name} is {length} lines (limit {limit})")
    print(f"{len(found)} function(s) over {limit} lines" if found else f"no function over {limit} lines")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
