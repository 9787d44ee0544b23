"""doc/design.md is the design page the code cites: every citation names a page of the repository
and, where it quotes a passage (doc/design.md "..."), a passage that page has."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DESIGN = ROOT / 'doc' / 'design.md'
CITED_IN = [ROOT / 'ros_ws' / 'src', ROOT / 'scripts', ROOT / 'tests']
#: a citation, then optionally 's and the quoted passage (quotes may span lines)
CITATION = re.compile(r'doc/design\.md(?:\'s)?(?: "([^"]+)")?')


def sources():
    """The .py files that may cite the page (this test names the patterns, so not itself)."""
    me = Path(__file__).resolve()
    return [p for folder in CITED_IN for p in sorted(folder.rglob('*.py')) if p.resolve() != me]


def _plain(text):
    """Text as read: markup (**, `) dropped, whitespace runs as one space."""
    return ' '.join(re.sub(r'\*\*|`', '', text).split())


def citations():
    found = []
    for path in sources():
        found += [(path.relative_to(ROOT), m.group(1)) for m in CITATION.finditer(_plain(path.read_text()))]
    return found


def test_the_design_page_has_every_passage_the_code_quotes():
    cited = citations()
    assert len(cited) >= 10, cited        # the page is cited across the packages and scripts
    page = _plain(DESIGN.read_text())
    missing = [f'{where}: "{quote}"' for where, quote in cited if quote and quote not in page]
    assert not missing, 'doc/design.md lacks passages the code quotes:\n' + '\n'.join(missing)


def test_no_citation_of_a_design_file_outside_the_repository():
    # the house plan beside the repository is not part of it: the code cites doc/design.md
    stale = [f'{p.relative_to(ROOT)}' for p in sources()
             if re.search(r'(?<![\w/])DESIGN\.md|\.\./shared', p.read_text())]
    assert not stale, f'cite doc/design.md instead in: {stale}'
