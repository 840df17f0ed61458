#!/usr/bin/env python3
"""docs/reference/cli.md is in step with the program's --help.

Usage: test_cli_reference.py DDEMAP_BINARY SOURCE_DIR

For every command that `ddemap --help` lists, docs/reference/cli.md must have a section
`## COMMAND` whose flag table (the rows starting with "| `-") names exactly the flags that
`ddemap COMMAND --help` prints in its option column: none missing, none that the program no
longer has. The fix for a failure is to rerun scripts/gen-cli-reference.py DDEMAP_BINARY.
"""
import re
import subprocess
import sys

FLAG = re.compile(r"--[a-z0-9][a-z0-9-]*")


def help_text(binary, *args):
    return subprocess.run([binary, *args, "--help"], capture_output=True, text=True, check=True).stdout


def commands(top):
    out, inside = [], False
    for line in top.splitlines():
        if line.startswith("Subcommands:"):
            inside = True
            continue
        if inside:
            m = re.match(r"^  (\S+)\s", line)
            if m:
                out.append(m.group(1))
            elif line.strip() and not line.startswith(" "):
                break
    return out


def help_flags(text):
    """The flags of the option column: lines '  -h,--help ...' or '  --ring N|inf=22 ...'."""
    flags = set()
    for line in text.splitlines():
        m = re.match(r"^  (-\S+)", line)
        if m:
            flags.update(FLAG.findall(m.group(1)))
    return flags


def sections(markdown):
    out, name = {}, None
    for line in markdown.splitlines():
        m = re.match(r"^## (\S+)\s*$", line)
        if m:
            name = m.group(1)
            out[name] = []
            continue
        if line.startswith("# "):
            name = None
        if name is not None:
            out[name].append(line)
    return out


def documented_flags(lines):
    flags = set()
    for line in lines:
        if line.startswith("| `-"):
            first = line.split("|")[1]
            flags.update(FLAG.findall(first))
    return flags


def main():
    binary, source = sys.argv[1], sys.argv[2]
    with open(source + "/docs/reference/cli.md", encoding="utf-8") as f:
        doc = sections(f.read())
    cmds = commands(help_text(binary))
    assert len(cmds) >= 10, "too few commands in ddemap --help: %r" % cmds
    failures = 0
    for c in cmds:
        if c not in doc:
            failures += 1
            print("FAIL  %s: no section '## %s' in docs/reference/cli.md" % (c, c))
            continue
        have = help_flags(help_text(binary, c))
        documented = documented_flags(doc[c])
        missing, stale = sorted(have - documented), sorted(documented - have)
        if missing or stale:
            failures += 1
            print("FAIL  %s: undocumented %s; documented but not in --help %s" % (c, missing or "none", stale or "none"))
        else:
            print("ok    %s: %d flags" % (c, len(have)))
    extra = sorted(set(doc) - set(cmds) - {"ddemap"})
    if extra:
        failures += 1
        print("FAIL  sections for commands ddemap does not have: %s" % ", ".join(extra))
    print("%d commands, %d failed%s" % (len(cmds), failures, " (regenerate with scripts/gen-cli-reference.py)" if failures else ""))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
