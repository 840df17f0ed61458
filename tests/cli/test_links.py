#!/usr/bin/env python3
"""Every relative link of the documentation resolves.

Usage: test_links.py SOURCE_DIR

Scans README.md, the other Markdown files at the top of SOURCE_DIR and every Markdown file under
docs/. Checked: inline links and images `[text](target)`, `![alt](target)`, reference
definitions `[label]: target`, and HTML `href="..."` / `src="..."`, outside code blocks and code
spans. Skipped: http(s)://, mailto: and other URLs with a scheme. A relative target must exist
inside SOURCE_DIR (a file or a folder); an anchor (`FILE.md#part`, or `#part` within the same
file) must match a heading of that Markdown file, slugged as GitHub does (lower case, punctuation
dropped, spaces to hyphens, -1, -2 ... for repeats), or an explicit `<a id="...">`.
"""
import os
import re
import sys

INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*(<[^>]*>|[^)\s]*)(?:\s+\"[^\"]*\")?\s*\)")
REFDEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*(\S+)")
HTML = re.compile(r"""(?:href|src)\s*=\s*["']([^"']+)["']""")
SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def strip_code(text):
    """The text with fenced blocks and code spans blanked (line numbers kept)."""
    out, fence = [], None
    for line in text.splitlines():
        m = re.match(r"^\s{0,3}(`{3,}|~{3,})", line)
        if fence is None and m:
            fence = m.group(1)[0] * len(m.group(1))
            out.append("")
            continue
        if fence is not None:
            if line.strip().startswith(fence):
                fence = None
            out.append("")
            continue
        out.append(re.sub(r"(`+)(?:(?!\1).)+?\1", "", line))
    return out


def slug(heading):
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links: their text
    text = re.sub(r"<[^>]+>", "", text).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        names, seen = set(), {}
        with open(path, encoding="utf-8") as f:
            text = f.read()
        fence = None
        for line in text.splitlines():
            m = re.match(r"^\s{0,3}(`{3,}|~{3,})", line)
            if m:
                fence = None if fence else m.group(1)
                continue
            if fence:
                continue
            h = re.match(r"^\s{0,3}#{1,6}\s+(.*?)\s*#*\s*$", line)
            if h:
                s = slug(h.group(1))
                n = seen.get(s, 0)
                seen[s] = n + 1
                names.add(s if n == 0 else "%s-%d" % (s, n))
            for a in re.findall(r"""<a\s+(?:id|name)\s*=\s*["']([^"']+)["']""", line):
                names.add(a)
        cache[path] = names
    return cache[path]


def targets(lines):
    for number, line in enumerate(lines, 1):
        for m in INLINE.finditer(line):
            yield number, m.group(1).strip("<>")
        m = REFDEF.match(line)
        if m:
            yield number, m.group(1).strip("<>")
        for m in HTML.finditer(line):
            yield number, m.group(1)


def markdown_files(source):
    files = sorted(os.path.join(source, f) for f in os.listdir(source) if f.endswith(".md"))
    for root, dirs, names in os.walk(os.path.join(source, "docs")):
        dirs.sort()
        files += sorted(os.path.join(root, n) for n in names if n.endswith(".md"))
    return files


def main():
    source = os.path.realpath(sys.argv[1])
    files = markdown_files(source)
    assert any(f.endswith("README.md") for f in files), "no README.md in %s" % source
    checked = failures = 0
    for path in files:
        rel = os.path.relpath(path, source)
        with open(path, encoding="utf-8") as f:
            lines = strip_code(f.read())
        for number, target in targets(lines):
            if not target or SCHEME.match(target):
                continue
            checked += 1
            file_part, _, anchor = target.partition("#")
            dest = os.path.realpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
            problem = None
            if not (dest == source or dest.startswith(source + os.sep)):
                problem = "points outside the repository"
            elif not os.path.exists(dest):
                problem = "no such file or folder"
            elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                problem = "no heading for the anchor #%s in %s" % (anchor, os.path.relpath(dest, source))
            if problem:
                failures += 1
                print("FAIL  %s:%d: (%s): %s" % (rel, number, target, problem))
    print("%d files, %d relative links checked, %d broken" % (len(files), checked, failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
