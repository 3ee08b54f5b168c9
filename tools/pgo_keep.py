#!/usr/bin/env python3
"""Keeps a committed profile's counts for the functions a training could not run.

Reads two LLVM text profiles: COMMITTED, the profile in use, and TRAINED, a training's counts
merged without --sparse (so it lists every instrumented function, those it never ran with zero
counts). Prints, as a text profile, COMMITTED's records of the functions TRAINED has but never
ran, their control flow unchanged (the same hash), under the names TRAINED gives them (a local
function's name starts with its codegen unit's, which a change elsewhere can renumber); names
them on stderr, the row renderers' first. Fails, naming them, when a row renderer COMMITTED
has counts for is neither run nor kept (its control flow changed, or it is gone): its counts
would be lost unless a CPU that runs it trains it. Other functions not kept (small ones the
row calls, changed) are compiled without counts.

    tools/pgo_keep.py COMMITTED TRAINED
"""

import sys


def records(path):
    """The header (the lines before the first record) and the records of a text profile,
    each a list of lines: the function's name, then "# Func Hash:" and the hash, then the
    counters."""
    with open(path, encoding="utf-8") as f:
        blocks = f.read().split("\n\n")
    lines = blocks[0].splitlines()
    start = next(
        (i for i, line in enumerate(lines) if not line.startswith(("#", ":"))), len(lines)
    )
    body = [lines[start:]] + [block.splitlines() for block in blocks[1:]]
    return lines[:start], [lines for lines in body if lines]


def counters(lines):
    """A record's counter values."""
    start = lines.index("# Counter Values:") + 1
    count = int(lines[lines.index("# Num Counters:") + 1])
    return [int(value) for value in lines[start : start + count]]


def symbol(name):
    """A record's function name without its codegen unit ("crate.hash-cgu.N;")."""
    return name.rpartition(";")[2]


def crate(name):
    """The crate of a local function's record ("crate.hash" of "crate.hash-cgu.N;"), or ""."""
    return name.partition(";")[0].rpartition("-cgu.")[0] if ";" in name else ""


def main():
    committed, trained = sys.argv[1:3]
    head, committed_records = records(committed)
    trained_head, trained_records = records(trained)
    if head != trained_head:
        sys.exit(f"{committed} and {trained} are profiles of different kinds")
    by_name = {lines[0]: lines for lines in trained_records}
    # The functions not run, by crate and symbol: a generic function has a copy in each
    # codegen unit that uses it, and a change elsewhere can renumber the units.
    not_run = {}
    for lines in trained_records:
        if not any(counters(lines)):
            not_run.setdefault((crate(lines[0]), symbol(lines[0])), []).append(lines)
    kept, lost = [], []
    for lines in committed_records:
        now = by_name.get(lines[0])
        if not any(counters(lines)) or (now is not None and any(counters(now))):
            continue
        copies = not_run.get((crate(lines[0]), symbol(lines[0])), [])
        same = [copy for copy in copies if copy[2] == lines[2]]
        same.sort(key=lambda copy: copy[0] != lines[0])  # its own name first
        if same:
            copies.remove(same[0])
            kept.append([same[0][0]] + lines[1:])
        elif "render_row" in lines[0]:
            lost.append(lines[0])
    if lost:
        names = "\n".join(f"  {name}" for name in lost)
        sys.exit(f"counts of {committed} this training cannot replace (changed or gone):\n{names}")
    print("\n".join(head))
    print("\n\n".join("\n".join(lines) for lines in kept))
    for lines in sorted(kept, key=lambda lines: "render_row" not in lines[0]):
        print(f"  kept: {lines[0]}", file=sys.stderr)


if __name__ == "__main__":
    main()
