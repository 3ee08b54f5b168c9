#!/usr/bin/env python3
"""Keeps counts from another profile for the functions a training could not run.

Reads two LLVM text profiles: COMMITTED, a profile with counts for what the training could not
run (the committed profile, or the training of tools/pgo.sh's stand-in for a level this CPU
lacks), and TRAINED, a training's counts merged without --sparse (so it lists every
instrumented function, those it never ran with zero counts). Prints, as a text profile,
COMMITTED's records of the functions TRAINED has but never ran, their control flow unchanged
(the same hash), under the names TRAINED gives them (a local function's name starts with its
codegen unit's, which a change elsewhere can renumber); names them on stderr, the row
renderers' first. Fails, naming them, when a row renderer COMMITTED has counts for is neither
run nor kept (its control flow changed, or it is gone): its counts would be lost unless a CPU
that runs it trains it. Other functions not kept (small ones the row calls, changed) are
compiled without counts. Tested by tools/test_pgo_keep.py.

    tools/pgo_keep.py COMMITTED TRAINED
"""

import sys


class ProfileError(Exception):
    """A profile this script cannot read, or counts it cannot keep."""


def parse(text, path):
    """The header (the lines before the first record) and the records of text profile
    `text` (read from `path`), each a list of lines: the function's name, "# Func Hash:", the
    hash, then its counters."""
    blocks = text.split("\n\n")
    lines = blocks[0].splitlines()
    start = next(
        (i for i, line in enumerate(lines) if not line.startswith(("#", ":"))), len(lines)
    )
    body = [lines[start:]] + [block.splitlines() for block in blocks[1:]]
    records = [record for record in body if record]
    for record in records:
        if len(record) < 3 or record[1] != "# Func Hash:":
            raise ProfileError(f"{path}: not an LLVM text profile record: {record[0]!r}")
        counters(record, path)
    return lines[:start], records


def counters(lines, path="the profile"):
    """A record's counter values."""
    try:
        start = lines.index("# Counter Values:") + 1
        count = int(lines[lines.index("# Num Counters:") + 1])
        return [int(value) for value in lines[start : start + count]]
    except ValueError as error:
        raise ProfileError(f"{path}: unreadable counters of {lines[0]!r}: {error}") from None


def symbol(name):
    """A record's function name without its codegen unit ("crate.hash-cgu.N;")."""
    return name.rpartition(";")[2]


def crate(name):
    """The crate of a local function's record ("crate.hash" of "crate.hash-cgu.N;"), or ""."""
    return name.partition(";")[0].rpartition("-cgu.")[0] if ";" in name else ""


def keep(committed, trained):
    """The records of `committed` to keep beside `trained` (each a list of records), renamed
    as `trained` names them; raises ProfileError naming the row renderers it cannot keep."""
    by_name = {lines[0]: lines for lines in trained}
    # By crate and symbol: a generic function has a copy in each codegen unit that uses it,
    # and a change elsewhere can renumber the units.
    ran, not_run = set(), {}
    for lines in trained:
        key = (crate(lines[0]), symbol(lines[0]))
        if any(counters(lines)):
            ran.add(key)
        else:
            not_run.setdefault(key, []).append(lines)
    kept, lost = [], []
    for lines in committed:
        key = (crate(lines[0]), symbol(lines[0]))
        now = by_name.get(lines[0])
        if not any(counters(lines)):
            continue
        if now is not None and any(counters(now)) or now is None and key in ran:
            continue  # the training has its counts
        same = [copy for copy in not_run.get(key, []) if copy[2] == lines[2]]
        same.sort(key=lambda copy: copy[0] != lines[0])  # its own name first
        if same:
            not_run[key].remove(same[0])
            kept.append([same[0][0]] + lines[1:])
        elif "render_row" in lines[0]:
            lost.append(lines[0])
    if lost:
        names = "\n".join(f"  {name}" for name in lost)
        raise ProfileError(f"counts this training cannot replace (changed or gone):\n{names}")
    return kept


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: tools/pgo_keep.py COMMITTED TRAINED")
    committed, trained = sys.argv[1:]
    try:
        profiles = []
        for path in (committed, trained):
            with open(path, encoding="utf-8") as f:
                profiles.append(parse(f.read(), path))
        (head, committed_records), (trained_head, trained_records) = profiles
        if head != trained_head:
            raise ProfileError(f"{committed} and {trained} are profiles of different kinds")
        kept = keep(committed_records, trained_records)
    except (OSError, ProfileError) as error:
        sys.exit(f"tools/pgo_keep.py: {error}")
    print("\n".join(head))
    print("\n\n".join("\n".join(lines) for lines in kept))
    for lines in sorted(kept, key=lambda lines: "render_row" not in lines[0]):
        print(f"  kept: {lines[0]}", file=sys.stderr)


if __name__ == "__main__":
    main()
