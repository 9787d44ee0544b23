"""External links in the documentation are the ones on the committed allow-list
(tests/data/external_links.txt): the build is offline, so a link to the outside is checked by a
person once, when it is listed, and a new or mistyped one fails here. Internal links and anchors
are the strict mkdocs build's (mkdocs.yml `validation:`, `make docs`)."""
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ALLOWED = REPO / 'tests/data/external_links.txt'
URL = re.compile(r'https?://[^\s)<>"\'`\]]+')


def doc_files():
    return sorted([*(REPO / 'doc').rglob('*.md'), *REPO.glob('ros_ws/src/*/doc/*.md'),
                   REPO / 'README.md'])


def urls_in(text):
    return {u.rstrip('.,;:') for u in URL.findall(text)}


def allowed():
    return {line.strip() for line in ALLOWED.read_text().splitlines()
            if line.strip() and not line.startswith('#')}


def test_every_external_link_is_on_the_allow_list_and_every_entry_is_used():
    used = {}
    for md in doc_files():
        for u in urls_in(md.read_text()):
            used.setdefault(u, []).append(str(md.relative_to(REPO)))
    assert used, 'no external link found: the scan is broken'
    unlisted = {u: pages for u, pages in used.items() if u not in allowed()}
    assert not unlisted, f'not in {ALLOWED.name} (check each by hand, then add it): {unlisted}'
    assert not allowed() - set(used), f'listed but used by no page: {allowed() - set(used)}'


def test_the_scan_finds_links_in_markdown_and_bare_text():
    text = ('See [Foxglove](https://foxglove.dev) and <https://example.org/a_b>, '
            'or https://example.org/x.html. Not `ftp://x`.')
    assert urls_in(text) == {'https://foxglove.dev', 'https://example.org/a_b',
                             'https://example.org/x.html'}
