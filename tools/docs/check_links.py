#!/usr/bin/env python3
"""Checks the docs' links: every page under docs/ is linked from README.md, every relative link of
README.md and docs/*.md points at a file that exists, and every #anchor at a heading of its page.
Prints each problem and exits 1 if there is one. Python 3 standard library only.

    tools/docs/check_links.py
"""

import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LINK = re.compile(r"\]\(([^)\s]+)\)")


def anchors(path):
    """GitHub's anchors for the headings of a markdown file."""
    found = set()
    with open(path, encoding="utf-8") as f:
        fenced = False
        for line in f:
            if line.startswith("```"):
                fenced = not fenced
            if fenced or not line.startswith("#"):
                continue
            text = line.lstrip("#").strip().lower()
            text = re.sub(r"[^\w\- ]", "", text)
            found.add(text.replace(" ", "-"))
    return found


def main():
    pages = ["README.md"] + sorted(os.path.join("docs", p) for p in os.listdir(os.path.join(ROOT, "docs"))
                                   if p.endswith(".md"))
    problems = []
    linked_from_readme = set()
    for page in pages:
        with open(os.path.join(ROOT, page), encoding="utf-8") as f:
            text = f.read()
        for target in LINK.findall(text):
            if re.match(r"^[a-z]+:", target):
                continue
            file_part, _, anchor = target.partition("#")
            resolved = os.path.normpath(os.path.join(os.path.dirname(page), file_part)) if file_part else page
            if page == "README.md":
                linked_from_readme.add(resolved)
            if not os.path.exists(os.path.join(ROOT, resolved)):
                problems.append(f"{page}: link to {target}: {resolved} does not exist")
            elif anchor and resolved.endswith(".md") and anchor not in anchors(os.path.join(ROOT, resolved)):
                problems.append(f"{page}: link to {target}: no heading '#{anchor}' in {resolved}")
    for page in pages[1:]:
        if page not in linked_from_readme:
            problems.append(f"README.md does not link to {page}")
    for p in problems:
        print(p)
    print(f"check_links: {len(pages)} pages, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
