"""kfd-compare's help: every option of every command says what it does and shows its default;
a dataset name without the datasets folder says where datasets are expected."""
import argparse
import os
import subprocess
import sys
import tempfile
import unittest

from kfd_tools import compare

EXE = None


def commands():
    ap = compare.build_parser()
    sub = next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


class HelpTest(unittest.TestCase):
    def test_every_option_has_a_description(self):
        for name, parser in commands().items():
            for action in parser._actions:
                if isinstance(action, argparse._HelpAction):
                    continue
                with self.subTest(command=name, option=action.dest):
                    self.assertTrue(action.help and len(action.help) > 5, action.dest)

    def test_every_default_is_shown(self):
        for name, parser in commands().items():
            text = parser.format_help()
            for action in parser._actions:
                d = action.default
                if (not action.option_strings or action.required or d is None
                        or isinstance(d, bool) or d is argparse.SUPPRESS):
                    continue
                with self.subTest(command=name, option=action.dest):
                    shown = " ".join(map(str, d)) if isinstance(d, list) else str(d)
                    fmt = parser._get_formatter()
                    self.assertIn("default", fmt._get_help_string(action), action.dest)
                    if shown and action.dest != "jobs":  # jobs: "every core"
                        # argparse wraps long paths at their hyphens: compare without spaces
                        self.assertIn("".join(shown.split()), "".join(text.split()))

    def test_a_dataset_name_without_datasets_says_where_they_are_expected(self):
        with tempfile.TemporaryDirectory() as tmp:
            missing = os.path.join(tmp, "no-datasets")
            exe = ["--exe", EXE] if EXE else []  # this build's (a tree may have no build/)
            p = subprocess.run([sys.executable, "-m", "kfd_tools.compare", "run", "--logs", "aces",
                                "--datasets", missing, "--out", os.path.join(tmp, "o"), "-q"]
                               + exe,
                               capture_output=True, text=True)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("the datasets folder " + missing + " does not exist", p.stderr)
            self.assertIn("--datasets DIR", p.stderr)


if __name__ == "__main__":
    EXE = sys.argv[1] if len(sys.argv) > 1 else None  # the kfd-icp-slam under test
    unittest.main(argv=sys.argv[:1])
