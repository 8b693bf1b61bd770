"""Nothing a page quotes is lost: every relative link of README.md and of the Markdown under docs/, results/ and
scenes/ names a file or folder that exists, and a link's #anchor a heading of the page it names (GitHub's slugs:
lower case, spaces to hyphens, punctuation but hyphens and underscores dropped, or an explicit <a id>).
Absolute links (http:, https:, mailto:) are not followed: no network here."""
import re
from pathlib import Path
from urllib.parse import unquote

from conftest import ROOT

LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
ANCHOR = re.compile(r"<a\s+id=\"([^\"]+)\"")
FENCE = re.compile(r"^(```|~~~)")


def pages():
    yield ROOT / "README.md"
    for top in ("docs", "results", "scenes"):
        yield from sorted((ROOT / top).rglob("*.md"))


def outside_fences(path: Path):
    """The page's lines outside code fences."""
    inside = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line.strip()):
            inside = not inside
            continue
        if not inside:
            yield line


def prose(path: Path):
    """The page's lines outside code fences, with inline code removed (a link shown as code is not a link)."""
    for line in outside_fences(path):
        yield re.sub(r"`[^`]*`", "", line)


def slug(heading: str) -> str:
    text = re.sub(r"<[^>]+>", "", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = text.strip().lower().replace("`", "")
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path) -> set:
    found, seen = set(), {}
    for line in outside_fences(path):
        m = HEADING.match(line)
        if m:
            s = slug(m.group(1))
            n = seen.get(s, 0)
            seen[s] = n + 1
            found.add(s if n == 0 else f"{s}-{n}")
        found.update(ANCHOR.findall(line))
    return found


def broken_links(page_list, root: Path) -> list:
    """Each relative link of the pages whose file or heading is missing, as "page: target (why)"."""
    broken, cache = [], {}
    for page in page_list:
        for line in prose(page):
            for target in LINK.findall(line):
                if re.match(r"^[a-z]+:", target):
                    continue
                file, _, anchor = target.partition("#")
                dest = (page.parent / unquote(file)).resolve() if file else page
                rel = page.relative_to(root)
                if not dest.exists():
                    broken.append(f"{rel}: {target} (no such file)")
                    continue
                if anchor and dest.suffix == ".md":
                    if dest not in cache:
                        cache[dest] = anchors(dest)
                    if anchor not in cache[dest]:
                        broken.append(f"{rel}: {target} (no heading #{anchor} in {dest.relative_to(root)})")
    return broken


def test_every_relative_link_names_what_exists():
    broken = broken_links(pages(), ROOT)
    assert not broken, "broken links:\n" + "\n".join(broken)


def test_the_checker_finds_a_broken_link(tmp_path):
    """A page with a missing file and a missing heading: both named; a heading with code and a link in a fence
    are not."""
    page = tmp_path / "page.md"
    (tmp_path / "there.md").write_text("# A heading, with `code`\n")
    page.write_text("[ok](there.md#a-heading-with-code) [gone](missing.md) [bad](there.md#nope)\n"
                    "```\n[in a fence](missing-too.md)\n```\n")
    assert broken_links([page], tmp_path) == ["page.md: missing.md (no such file)",
                                              "page.md: there.md#nope (no heading #nope in there.md)"]
