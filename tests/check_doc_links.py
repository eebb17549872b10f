"""Every relative link of the manuals (README.md and docs/*.md) reaches a file of the repository, and every
#anchor a heading of its target (GitHub's rule: lower case, punctuation dropped, spaces as '-'). Code spans and
fenced blocks are not links. Fails listing each broken link as FILE: TARGET (what is missing).
Usage: check_doc_links.py SOURCE_DIR"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1]).resolve()


def without_code(text):
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def anchors(path):
    found = set()
    inside = False
    for line in path.read_text(encoding="utf-8").split("\n"):
        if line.startswith("```"):
            inside = not inside
        elif not inside and re.match(r"^#+ ", line):
            heading = line.lstrip("#").strip().lower()
            found.add(re.sub(r"[^\w\- ]", "", heading).replace(" ", "-"))
    return found


broken = []
for manual in [root / "README.md", *sorted((root / "docs").glob("*.md"))]:
    for target in re.findall(r"\]\(([^)\s]+)\)", without_code(manual.read_text(encoding="utf-8"))):
        if re.match(r"^[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        file = (manual.parent / path).resolve() if path else manual
        if not file.exists():
            broken.append(f"{manual.relative_to(root)}: {target} (no such file)")
        elif anchor and file.suffix == ".md" and anchor not in anchors(file):
            broken.append(f"{manual.relative_to(root)}: {target} (no heading #{anchor} in {file.relative_to(root)})")
for line in broken:
    print(f"broken link: {line}")
sys.exit(1 if broken else 0)
