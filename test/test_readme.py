"""The README stays a page for users: at most 300 lines, no measurements or commit hashes (those
live in docs/performance.md), and every link of the READMEs and of docs/ leads to a file that
exists (the reference moved to docs/; a link left behind would point nowhere)."""
import glob
import os
import re

from acti_bringup.harness import ROOT

README = os.path.join(ROOT, "README.md")
MAX_LINES = 300
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def read(path: str) -> str:
    with open(path, encoding="utf-8") as f:
        return f.read()


def test_the_readme_has_at_most_300_lines():
    assert len(read(README).splitlines()) <= MAX_LINES


def test_the_readme_names_no_commit():
    hashes = re.findall(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b", read(README))
    assert not hashes, f"commits belong in docs/performance.md: {hashes}"


def test_every_link_of_the_readmes_and_docs_leads_to_a_file():
    pages = [README, os.path.join(ROOT, "strolic", "README.md"),
             *glob.glob(os.path.join(ROOT, "docs", "*.md"))]
    broken = [f"{os.path.relpath(page, ROOT)}: {target}" for page in pages
              for target in LINK.findall(read(page))
              if "://" not in target
              and not os.path.exists(os.path.join(os.path.dirname(page), target))]
    assert not broken, broken
