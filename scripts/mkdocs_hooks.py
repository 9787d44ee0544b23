"""mkdocs hooks of the documentation site (mkdocs.yml): the packages' science pages, the API
reference and the parameter reference (guide/parameters.md, from the nodes' parameter schemas by
scripts/gen_param_files.py) become pages of the site, and links into the repository are checked.

The Markdown under doc/ is written to read well on the repository's web view too, so it links
source files by their repository path (``../../ros_ws/src/ship_sim/ship_sim/frames.py``). The site
cannot serve those files: such a link becomes the path in code type, after checking that the file
exists (a missing one is a warning, which fails the strict build). Links to a package's
``doc/*.md`` become links to its page under ``science/``.
"""
import importlib.util
import logging
import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File

log = logging.getLogger('mkdocs.plugins.shipnav')

REPO = Path(__file__).resolve().parent.parent
PACKAGES = ('ship_sim', 'ship_guidance', 'ship_autopilot', 'ship_planner', 'ship_mission')
# Markdown links outside code: [text](target) where target is relative (no scheme, no anchor-only).
LINK = re.compile(r'(!?)\[([^\]]*)\]\((?![a-z][a-z0-9+.-]*:|#)([^)\s]+?)(#[^)\s]*)?\)')
FENCE = re.compile(r'^(```|~~~)')


def science_pages():
    """(site path, source file) of every package's doc/*.md."""
    for pkg in PACKAGES:
        for md in sorted((REPO / 'ros_ws/src' / pkg / 'doc').glob('*.md')):
            yield f'science/{md.stem}.md', md


def api_modules():
    """Dotted names of the packages' public modules (no nodes' ROS glue is left out: it is
    documented like the rest), sorted by package then module."""
    for pkg in PACKAGES:
        base = REPO / 'ros_ws/src' / pkg
        for py in sorted((base / pkg).rglob('*.py')):
            rel = py.relative_to(base).with_suffix('')
            parts = rel.parts
            if parts[-1] == '__init__' or any(p.startswith('_') for p in parts):
                continue
            yield pkg, '.'.join(parts)


def _sibling_script(name):
    """The module scripts/<name>.py, loaded from its file: mkdocs loads this hook from its file
    too, so scripts/ is not on the path (the packages come from the sourced install)."""
    spec = importlib.util.spec_from_file_location(name, Path(__file__).with_name(f'{name}.py'))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def on_files(files, config):
    # The parameter reference, rendered from the nodes' schemas at every build: it cannot drift.
    reference_markdown = _sibling_script('gen_param_files').reference_markdown
    files.append(File.generated(config, 'guide/parameters.md', content=reference_markdown()))
    for uri, src in science_pages():
        files.append(File.generated(config, uri, abs_src_path=str(src)))
    by_pkg = {}
    for pkg, mod in api_modules():
        by_pkg.setdefault(pkg, []).append(mod)
    for pkg, mods in by_pkg.items():
        body = [f'# `{pkg}`\n', f'Generated from the docstrings of `ros_ws/src/{pkg}`.\n']
        for mod in mods:
            body.append(f'## `{mod}`\n\n::: {mod}\n    options:\n      show_root_heading: false\n')
        files.append(File.generated(config, f'reference/{pkg}.md', content='\n'.join(body)))
    return files


def _repo_target(page_src: Path, target: str) -> Path:
    return (page_src.parent / target).resolve()


def on_page_markdown(markdown, page, config, files):
    src = page.file.abs_src_path
    if src is None:
        return markdown
    src = Path(src)
    science = {str(s.resolve()): uri for uri, s in science_pages()}
    out, in_code = [], False
    for line in markdown.splitlines(keepends=True):
        if FENCE.match(line.lstrip()):
            in_code = not in_code
        if not in_code:
            line = LINK.sub(lambda m: _rewrite(m, src, page, science), line)
        out.append(line)
    return ''.join(out)


def _rewrite(m, src, page, science):
    bang, text, target, frag = m.group(1), m.group(2), m.group(3), m.group(4) or ''
    path = _repo_target(src, target)
    docs_dir = REPO / 'doc'
    if path.is_relative_to(docs_dir):
        return m.group(0)          # a page or asset of the site: mkdocs checks it
    if str(path) in science:
        here = posixpath.dirname(page.file.src_uri)
        return f'{bang}[{text}]({posixpath.relpath(science[str(path)], here or ".")}{frag})'
    if not path.exists():
        log.warning('%s links to %s, which is not in the repository', page.file.src_uri, target)
        return m.group(0)
    if not path.is_relative_to(REPO):
        log.warning('%s links outside the repository: %s', page.file.src_uri, target)
    shown = path.relative_to(REPO).as_posix() if path.is_relative_to(REPO) else target
    if bang:
        log.warning('%s shows an image outside doc/: %s', page.file.src_uri, target)
    return text if text.strip('`') == shown else f'{text} (`{shown}`)'
