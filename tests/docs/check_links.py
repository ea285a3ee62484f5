#!/usr/bin/env python3
"""Checks the links of dpoint's user documentation (issue #23: every link in README and docs resolves).

Usage: python3 tests/docs/check_links.py REPO_ROOT

Reads README.md, docs/*.md and bench/results/README.md under REPO_ROOT. For every Markdown link or
image, inline `[text](target)` / `![alt](target)` or a reference definition `[label]: target`,
outside code blocks and code spans:
  - http:, https:, mailto: (any scheme) targets are skipped;
  - a relative path must name a file or folder that exists relative to the Markdown file;
  - an anchor (`#anchor`, `file.md#anchor`) must be produced by a heading of that file, the way
    GitHub makes anchors (lower case, punctuation dropped, spaces to hyphens, repeats numbered -1,
    -2, ...).
Prints `FILE:LINE: broken link TARGET` for each broken one and exits 1, else prints
`N links checked, 0 broken` and exits 0. Python 3 standard library only.
"""
import os
import re
import sys
import urllib.parse

FENCE = re.compile(r"^\s{0,3}(```+|~~~+)")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
# `](target)` or `](target "title")`; the text before it may hold brackets (an image inside a link).
INLINE = re.compile(r"\]\(\s*(<[^>]*>|[^)\s]+)(?:\s+(?:\"[^\"]*\"|'[^']*'|\([^)]*\)))?\s*\)")
DEFINITION = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)")
SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


def blank_code_spans(line):
    """The line with each inline code span's content replaced by spaces (columns kept)."""
    return CODE_SPAN.sub(lambda m: " " * len(m.group(0)), line)


def slug(heading_text):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading_text)  # links and images: their text
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML tags
    text = text.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)  # keep letters, digits, _, -, space
    return text.replace(" ", "-")


def markdown_lines(path):
    """(line number, text) of the lines outside fenced code blocks."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    fence = None
    for number, line in enumerate(lines, 1):
        m = FENCE.match(line)
        if fence is not None:
            if m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence):
                fence = None
            continue
        if m:
            fence = m.group(1)
            continue
        yield number, line


_anchor_cache = {}


def anchors(path):
    path = os.path.realpath(path)
    if path not in _anchor_cache:
        found = set()
        seen = {}
        for _, line in markdown_lines(path):
            m = HEADING.match(line)
            if not m:
                continue
            base = slug(m.group(2).replace("`", ""))
            count = seen.get(base, 0)
            seen[base] = count + 1
            found.add(base if count == 0 else f"{base}-{count}")
        _anchor_cache[path] = found
    return _anchor_cache[path]


def links(path):
    """(line number, target) of every link and image in a Markdown file."""
    for number, line in markdown_lines(path):
        text = blank_code_spans(line)
        for m in INLINE.finditer(text):
            yield number, m.group(1)
        m = DEFINITION.match(text)
        if m:
            yield number, m.group(1)


def broken(md_path, target):
    """True when `target`, a link in md_path, does not resolve."""
    target = target.strip("<>")
    path_part, _, anchor = target.partition("#")
    path_part = urllib.parse.unquote(path_part)
    if path_part:
        resolved = os.path.normpath(os.path.join(os.path.dirname(md_path), path_part))
        if not os.path.exists(resolved):
            return True
    else:
        resolved = md_path
    if anchor:
        if not resolved.endswith(".md") or os.path.isdir(resolved):
            return False  # anchors into other kinds of files are not checked
        return urllib.parse.unquote(anchor).lower() not in anchors(resolved)
    return False


def main(argv):
    if len(argv) != 2:
        print("usage: check_links.py REPO_ROOT", file=sys.stderr)
        return 2
    root = argv[1]
    files = [os.path.join(root, "README.md")]
    docs = os.path.join(root, "docs")
    if os.path.isdir(docs):
        files += sorted(os.path.join(docs, name) for name in os.listdir(docs) if name.endswith(".md"))
    files.append(os.path.join(root, "bench", "results", "README.md"))
    checked = 0
    bad = 0
    for md in files:
        if not os.path.isfile(md):
            print(f"{os.path.relpath(md, root)}:0: missing Markdown file")
            bad += 1
            continue
        for number, target in links(md):
            if SCHEME.match(target):
                continue  # http:, https:, mailto: and any other scheme
            checked += 1
            if broken(md, target):
                print(f"{os.path.relpath(md, root)}:{number}: broken link {target}")
                bad += 1
    if bad:
        print(f"{checked} links checked, {bad} broken")
        return 1
    print(f"{checked} links checked, 0 broken")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
