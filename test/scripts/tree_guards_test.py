"""Guards on the tree's shape (issue 34), each checked on the real tree and each shown able to
fail on a hand-made one:
  - the paper's folder (libkfd/.../paper) includes only std headers, itself, and the framework's
    scan and error types: nothing of kfd's own algorithms, no OS or MRPT header;
  - the paper's stages (distance, keyframe, denoise) include only the paper, the framework,
    the stages' shared headers and the keyframe rule with its guards (off in the paper
    presets): nothing of kfd's view selector or denoisers;
  - no OS header in the algorithm folders (paper, algorithms, stages, pipeline);
  - no Python file inserts into sys.path (shared test support is imported by name);
  - scripts/ci/longest.py finds functions and files by their length, comments and strings
    ignored.
Usage: tree_guards_test.py"""
import os
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LONGEST = os.path.join(ROOT, "scripts", "ci", "longest.py")
ALGORITHM_FOLDERS = ("paper", "algorithms", "stages", "filters", "pipeline")
PAPER_MAY_INCLUDE = re.compile(r'^(<[a-z_]+>|"kfd/paper/[a-z_]+\.h"|"kfd/pipeline/(scan|error)\.h")$')
PAPER_STAGES = ("distance_stage", "keyframe_stage", "denoise_stage")
PAPER_STAGE_MAY_INCLUDE = re.compile(
    r'^(<[a-z_]+>|"kfd/(paper|pipeline)/[a-z_]+\.h"|"kfd/stages/(%s|denoise_result)\.h"|'
    r'"guard_keys\.h"|"kfd/algorithms/(keyframe_selector|keyframe_guards)\.h")$'
    % "|".join(PAPER_STAGES))
OS_HEADERS = re.compile(r"^<(unistd|fcntl|signal|dirent|pthread|sys/.*|filesystem|fstream|"
                        r"mrpt/.*|ros/.*|rosbag/.*)(\.h)?>$")


def folder_files(root, folder):
    for sub in ("include/kfd", "src"):
        d = os.path.join(root, "libkfd", sub, folder)
        if os.path.isdir(d):
            for f in sorted(os.listdir(d)):
                yield os.path.join(d, f)


def includes(path):
    with open(path, encoding="utf-8") as f:
        return [m.group(1) for m in re.finditer(r'^\s*#\s*include\s+(\S+)', f.read(), re.M)]


def paper_violations(root):
    return ["%s: %s" % (os.path.relpath(p, root), i) for p in folder_files(root, "paper")
            for i in includes(p) if not PAPER_MAY_INCLUDE.match(i)]


def paper_stage_violations(root):
    return ["%s: %s" % (os.path.relpath(p, root), i) for p in folder_files(root, "stages")
            if os.path.splitext(os.path.basename(p))[0] in PAPER_STAGES
            for i in includes(p) if not PAPER_STAGE_MAY_INCLUDE.match(i)]


def os_violations(root):
    return ["%s: %s" % (os.path.relpath(p, root), i) for folder in ALGORITHM_FOLDERS
            for p in folder_files(root, folder) for i in includes(p) if OS_HEADERS.match(i)]


def path_inserts(root):
    found = []
    for base, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if not d.startswith(".") and d != "build"]
        for f in files:
            if f.endswith(".py"):
                p = os.path.join(base, f)
                with open(p, encoding="utf-8", errors="replace") as fh:
                    if re.search(r"^\s*sys\.path\.insert\s*\(", fh.read(), re.M):
                        found.append(os.path.relpath(p, root))
    return found


def write(root, rel, text):
    p = os.path.join(root, rel)
    os.makedirs(os.path.dirname(p), exist_ok=True)
    with open(p, "w") as f:
        f.write(text)


class TreeGuards(unittest.TestCase):
    def test_the_paper_folder_includes_only_std_and_the_scan_types(self):
        self.assertTrue(list(folder_files(ROOT, "paper")), "no paper folder")
        self.assertEqual(paper_violations(ROOT), [])

    def test_the_papers_stages_run_only_the_paper(self):
        self.assertEqual(len([p for p in folder_files(ROOT, "stages")
                              if os.path.splitext(os.path.basename(p))[0] in PAPER_STAGES]), 6)
        self.assertEqual(paper_stage_violations(ROOT), [])

    def test_the_algorithm_folders_include_no_os_header(self):
        self.assertEqual(os_violations(ROOT), [])

    def test_no_python_file_inserts_into_sys_path(self):
        self.assertEqual(path_inserts(ROOT), [])

    def test_each_guard_fails_on_a_tree_that_breaks_it(self):
        with tempfile.TemporaryDirectory() as t:
            write(t, "libkfd/src/paper/a.cpp", '#include "kfd/paper/a.h"\n#include <vector>\n')
            write(t, "libkfd/include/kfd/paper/a.h", '#include "kfd/pipeline/scan.h"\n')
            self.assertEqual(paper_violations(t), [])
            write(t, "libkfd/src/stages/denoise_stage.cpp",
                  '#include "kfd/stages/denoise_stage.h"\n#include "kfd/paper/clusters.h"\n')
            self.assertEqual(paper_stage_violations(t), [])
            write(t, "libkfd/include/kfd/stages/denoise_stage.h",
                  '#include "kfd/algorithms/evidence_filter.h"\n')
            self.assertEqual(paper_stage_violations(t), [
                'libkfd/include/kfd/stages/denoise_stage.h: "kfd/algorithms/evidence_filter.h"'])
            write(t, "libkfd/include/kfd/paper/b.h", '#include "kfd/algorithms/view_selector.h"\n')
            write(t, "libkfd/src/algorithms/c.cpp", "#include <unistd.h>\n")
            # the offending line built from parts: the repository itself holds none
            write(t, "tools/x.py", "import sys\nsys.path." + "insert(0, 'here')\n")
            self.assertEqual(paper_violations(t),
                             ['libkfd/include/kfd/paper/b.h: "kfd/algorithms/view_selector.h"'])
            self.assertEqual(os_violations(t), ["libkfd/src/algorithms/c.cpp: <unistd.h>"])
            self.assertEqual(path_inserts(t), ["tools/x.py"])


class Longest(unittest.TestCase):
    def run_longest(self, *args):
        return subprocess.run([sys.executable, LONGEST] + list(args), capture_output=True,
                              text=True)

    def test_it_measures_functions_and_files_and_ignores_braces_in_comments_and_strings(self):
        body = "\n".join("    x += %d;" % i for i in range(70))
        text = ("namespace kfd {\n// { not a brace\nconst char* s = \"{\";\n"
                "struct S {\n    int f() const { return 1; }\n};\n"
                "int longOne(int x) {\n" + body + "\n    return x;\n}\n}  // namespace kfd\n")
        with tempfile.TemporaryDirectory() as t:
            write(t, "a.cpp", text)
            r = self.run_longest("--top", "5", t)
            self.assertEqual(r.returncode, 0, r.stderr)
            lines = r.stdout.splitlines()
            self.assertRegex(lines[1], r"^\s+73\s+.*a\.cpp:7 longOne$")
            self.assertRegex(lines[2], r"^\s+1\s+.*a\.cpp:5 f$")
            r = self.run_longest("--max-function", "60", t)
            self.assertEqual(r.returncode, 1)
            self.assertIn("over the limits: 1", r.stdout)
            self.assertEqual(self.run_longest("--max-function", "80", t).returncode, 0)

    def test_it_reads_the_whole_tree(self):
        r = self.run_longest("--top", "3")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("libkfd/", r.stdout)


if __name__ == "__main__":
    unittest.main(verbosity=2)
