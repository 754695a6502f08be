#!/usr/bin/python3
"""ctest clang_format: every file of tests/format/formatted_files.txt is formatted by the
repository's .clang-format (clang-format --dry-run --Werror leaves it unchanged).

    check_format.py SOURCE_DIR [--list FILE]

Exit 0: all listed files are formatted; 1: some are not (each is named with the first lines
clang-format would change, and the command that fixes it); 2: the check could not run (no
clang-format, a listed file is missing). The style was written for clang-format 14 (Debian 12's
package `clang-format`); another major version may format some constructs differently, which
the message then says.
"""
import argparse
import difflib
import os
import re
import shutil
import subprocess
import sys


def find_clang_format():
    for name in ("clang-format-14", "clang-format"):
        path = shutil.which(name)
        if path:
            return path
    return None


def read_list(path):
    files = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                files.append(line)
    return files


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("source_dir")
    ap.add_argument("--list", default=None, help="allow-list (default: tests/format/formatted_files.txt)")
    args = ap.parse_args()
    root = os.path.abspath(args.source_dir)
    listing = args.list or os.path.join(root, "tests", "format", "formatted_files.txt")

    tool = find_clang_format()
    if tool is None:
        print("check_format: clang-format not found (apt-get install clang-format; deploy/install-deps.sh installs it)")
        return 2
    version = subprocess.run([tool, "--version"], capture_output=True, text=True).stdout.strip()
    major = re.search(r"version (\d+)", version)
    if not os.path.isfile(os.path.join(root, ".clang-format")):
        print(f"check_format: no .clang-format in {root}")
        return 2

    files = read_list(listing)
    missing = [f for f in files if not os.path.isfile(os.path.join(root, f))]
    if missing:
        print("check_format: listed files that do not exist (remove them from "
              f"{os.path.relpath(listing, root)}):\n  " + "\n  ".join(missing))
        return 2
    dupes = sorted({f for f in files if files.count(f) > 1})
    if dupes:
        print("check_format: listed twice: " + ", ".join(dupes))
        return 2

    bad = []
    for rel in files:
        path = os.path.join(root, rel)
        # --style=file finds the repository's .clang-format from the file's folder upwards.
        r = subprocess.run([tool, "--style=file", "--dry-run", "--Werror", path], capture_output=True, text=True)
        if r.returncode != 0:
            with open(path, encoding="utf-8") as f:
                before = f.read().splitlines()
            after = subprocess.run([tool, "--style=file", path], capture_output=True, text=True).stdout.splitlines()
            diff = list(difflib.unified_diff(before, after, rel, rel + " (formatted)", n=0, lineterm=""))
            bad.append((rel, diff))

    print(f"check_format: {len(files)} files checked with {version}")
    if not bad:
        return 0
    for rel, diff in bad:
        print(f"\n{rel} is not formatted; first changes clang-format would make:")
        print("\n".join(diff[:24]) + ("\n  ..." if len(diff) > 24 else ""))
    print(f"\ncheck_format: {len(bad)} of {len(files)} listed files are not formatted. Fix with\n"
          f"  (cd {root} && {os.path.basename(tool)} -i --style=file " + " ".join(r for r, _ in bad) + ")")
    if major and major.group(1) != "14":
        print(f"(the style is written for clang-format 14; this is {major.group(1)}, which may differ)")
    return 1


if __name__ == "__main__":
    sys.exit(main())
