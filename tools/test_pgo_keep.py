#!/usr/bin/env python3
"""Tests of tools/pgo_keep.py on small text profiles: `python3 -m unittest tools/test_pgo_keep.py`
(CI runs them)."""

import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pgo_keep  # noqa: E402

HEAD = "# IR level Instrumentation Flag\n:ir\n"
V4 = "_ZN13pathlight_cpu3row25render_row_x86_64_v4_gfni17hf1d7E"
V3 = "_ZN13pathlight_cpu3row20render_row_x86_64_v317h25e7E"
DROP = "_ZN4core3ptr13drop_in_place17hbbb4E"


def record(name, hash_, counts):
    """One function's record in LLVM's text format."""
    values = "\n".join(str(c) for c in counts)
    return f"{name}\n# Func Hash:\n{hash_}\n# Num Counters:\n{len(counts)}\n# Counter Values:\n{values}"


def profile(*records):
    """A text profile of `records`, parsed."""
    return pgo_keep.parse(HEAD + "\n\n".join(records) + "\n", "test")[1]


def cgu(n, symbol):
    """`symbol` as a local function of pathlight_cpu's codegen unit `n` names it."""
    return f"pathlight_cpu.b2bb-cgu.{n:02};{symbol}"


class KeepTests(unittest.TestCase):
    def names(self, kept):
        return [(lines[0], lines[2], pgo_keep.counters(lines)) for lines in kept]

    def test_the_row_not_run_keeps_its_counts_under_its_new_unit(self):
        committed = profile(
            record(cgu(0, V4), 11, [5, 7]), record(cgu(1, V3), 12, [3, 4])
        )
        trained = profile(record(cgu(4, V4), 11, [0, 0]), record(cgu(2, V3), 12, [6, 8]))
        self.assertEqual(self.names(pgo_keep.keep(committed, trained)), [(cgu(4, V4), "11", [5, 7])])

    def test_a_row_whose_control_flow_changed_or_is_gone_fails_naming_it(self):
        committed = profile(record(cgu(0, V4), 11, [5, 7]))
        for trained in (profile(record(cgu(0, V4), 99, [0, 0])), profile(record(cgu(1, V3), 12, [1]))):
            with self.assertRaisesRegex(pgo_keep.ProfileError, "render_row_x86_64_v4"):
                pgo_keep.keep(committed, trained)

    def test_copies_of_a_generic_function_keep_the_counts_of_the_same_hash(self):
        committed = profile(
            record(cgu(3, DROP), 1, [2]), record(cgu(5, DROP), 2, [9]), record(cgu(6, DROP), 1, [0])
        )
        trained = profile(
            record(cgu(3, DROP), 2, [0]), record(cgu(7, DROP), 1, [0]), record(cgu(8, DROP), 1, [0])
        )
        kept = self.names(pgo_keep.keep(committed, trained))
        self.assertEqual(sorted(kept), [(cgu(3, DROP), "2", [9]), (cgu(7, DROP), "1", [2])])

    def test_functions_the_training_ran_or_never_counted_are_not_kept(self):
        committed = profile(record(cgu(0, DROP), 1, [4]), record("plain", 3, [0, 0]))
        trained = profile(record(cgu(9, DROP), 1, [1]), record("plain", 3, [0, 0]))
        self.assertEqual(pgo_keep.keep(committed, trained), [])

    def test_bad_input_is_named(self):
        with self.assertRaisesRegex(pgo_keep.ProfileError, "test: not an LLVM text profile"):
            pgo_keep.parse(HEAD + "name\n# Num Counters:\n1\n", "test")
        with self.assertRaisesRegex(pgo_keep.ProfileError, "unreadable counters of 'f'"):
            pgo_keep.parse(HEAD + "f\n# Func Hash:\n1\n# Num Counters:\nx\n", "test")
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "pgo_keep.py")
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "committed.proftext")
            with open(path, "w", encoding="utf-8") as f:
                f.write(HEAD + record(cgu(0, V4), 11, [5]) + "\n")
            run = subprocess.run(
                [sys.executable, script, path, os.path.join(tmp, "missing")],
                capture_output=True,
                text=True,
            )
        self.assertEqual(run.returncode, 1)
        self.assertIn("missing", run.stderr)


if __name__ == "__main__":
    unittest.main()
