#!/usr/bin/python3
"""The longest functions and files of kfd's C++ code (issue 34: "none over 60 lines and none over
~600 lines"). A function is a brace-delimited body that opens at namespace or class level after
a parameter list; lambdas and blocks inside it count as part of it. Comments and string literals
are ignored while braces are matched. Lines are counted from the signature's first line to the
closing brace, both included.
Usage: scripts/ci/longest.py [--top N] [--max-function L] [--max-file L] [DIR ...]
  DIR defaults to libkfd apps ros (relative to the repository). Prints the N (20) longest of
  each; with --max-function / --max-file, exits 1 when any is longer and lists those."""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXTS = (".h", ".hpp", ".cpp", ".cc", ".in")


def strip(text):
    """text with comments and string/char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = ")" + (m.group(1) if m else "") + '"'
            j = text.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(name, first line, last line) of every function body in text (1-based lines)."""
    code = strip(text)
    stack = []  # kinds of the open braces: ns, class, func, block
    found = []
    head_start = 0  # offset where the current declaration's text starts
    for i, c in enumerate(code):
        if c == "{":
            head = code[head_start:i]
            outer = stack[-1][0] if stack else "ns"
            words = head.split()
            if outer in ("ns", "class"):
                if re.search(r"\bnamespace\b", head) or re.match(r'\s*extern\s*$', head):
                    kind = "ns"
                elif re.search(r"\b(class|struct|union|enum)\b", head) and "(" not in head:
                    kind = "class"
                elif "(" in head and not re.search(r"=\s*$", head):
                    kind = "func"
                else:
                    kind = "block"
            else:
                kind = "block"
            first = code.count("\n", 0, head_start + len(head) - len(head.lstrip())) + 1
            stack.append((kind, first, head.strip()))
            head_start = i + 1
        elif c == "}":
            if stack:
                kind, first, head = stack.pop()
                if kind == "func":
                    name = re.sub(r"\s+", " ", head.split("(")[0]).split(" ")[-1]
                    found.append((name, first, code.count("\n", 0, i) + 1))
            head_start = i + 1
        elif c == ";":
            head_start = i + 1
        elif c == ":" and stack and stack[-1][0] == "class" and \
                re.search(r"\b(public|private|protected)\s*$", code[head_start:i]):
            head_start = i + 1
        elif c == "#" and code[head_start:i].strip() == "":  # a preprocessor line
            j = code.find("\n", i)
            head_start = j + 1 if j >= 0 else i + 1
    return found


def sources(dirs):
    for d in dirs:
        for base, _, files in os.walk(d):
            for f in sorted(files):
                if f.endswith(EXTS):
                    yield os.path.join(base, f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dirs", nargs="*")
    ap.add_argument("--top", type=int, default=20)
    ap.add_argument("--max-function", type=int)
    ap.add_argument("--max-file", type=int)
    a = ap.parse_args()
    dirs = a.dirs or [os.path.join(ROOT, d) for d in ("libkfd", "apps", "ros")]
    funcs, files = [], []
    for path in sources(dirs):
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        rel = os.path.relpath(path, ROOT)
        files.append((text.count("\n"), rel))
        for name, first, last in functions(text):
            funcs.append((last - first + 1, "%s:%d %s" % (rel, first, name)))
    funcs.sort(reverse=True)
    files.sort(reverse=True)
    print("longest functions (lines):")
    for n, where in funcs[:a.top]:
        print("%6d  %s" % (n, where))
    print("longest files (lines):")
    for n, rel in files[:a.top]:
        print("%6d  %s" % (n, rel))
    over = [w for n, w in funcs if a.max_function and n > a.max_function]
    over += [r for n, r in files if a.max_file and n > a.max_file]
    if over:
        print("over the limits: %d" % len(over))
        return 1
    print("%d functions, %d files" % (len(funcs), len(files)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
