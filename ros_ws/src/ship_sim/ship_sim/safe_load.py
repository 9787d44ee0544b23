"""The one bounded reader of the project's input files and text parameters (YAML and JSON).

Every file or text parameter the project reads (scenario, sweep and route files, node
configuration, traffic_node's ``targets``, the Imazu cases, ...) goes through this module, so
a hostile or mistaken input ends in one line naming the file and the line, never in a hang, a
full memory or a traceback:

- files: only regular files (a FIFO, a directory or a device is refused before it is read, so
  nothing blocks: ``check_regular_file``, ``open_regular_file``, ``read_regular_file``), of at
  most MAX_FILE_BYTES, and for text only UTF-8;
- nesting: at most MAX_DEPTH levels of lists and mappings (deeper input would end in a
  RecursionError inside the parser);
- size after aliases: at most MAX_NODES values, counting what every YAML alias (``*a``)
  stands for, so a few lines of nested aliases (a "billion laughs") are refused while they are
  parsed instead of expanding into gigabytes; an alias inside its own anchor is refused too;
- numbers: at most MAX_NUMBER_CHARS characters (a 5000-digit integer is beyond what int()
  accepts, and no physical quantity needs more than a few dozen digits);
- duplicate keys: a mapping that gives a key twice is refused, naming the key and both lines
  (YAML would keep the last silently; JSON likewise).

Names that become part of ROS names (vessel namespaces, light-target names) are checked as ROS
checks a topic name token (``ros_name_problem``): ASCII letters, digits and underscores, not
starting with a digit. ``str.isidentifier`` is not that test: it accepts letters of every
alphabet, which ROS then refuses as an "invalid topic name" after the graph has started.

YAML numbers: YAML 1.1 (PyYAML) reads ``1e9`` (no dot) as text; ``Loader`` reads it as the
number YAML 1.2 and every other reader would see.

Every refusal is an InputError (a ValueError): ``detail``, ``line`` (1-based or None) and
``file`` (or None); str() is ``<file>:<line>: <detail>`` with the parts that are known.
"""
import json
import os
import re
import stat

import yaml

#: Largest input file (bytes) read.
MAX_FILE_BYTES = 10_000_000
#: Deepest nesting of lists and mappings.
MAX_DEPTH = 64
#: Most values (scalars, lists, mappings) in one document, counted after alias expansion: a
#: thousand times the largest shipped file, and small enough that the composer (Python, where
#: the checks are) gets through the worst case in seconds, not minutes.
MAX_NODES = 200_000
#: Longest number literal (characters).
MAX_NUMBER_CHARS = 100

_FILE_KINDS = ((stat.S_ISDIR, 'a directory'), (stat.S_ISFIFO, 'a FIFO (named pipe)'),
               (stat.S_ISSOCK, 'a socket'), (stat.S_ISCHR, 'a character device'),
               (stat.S_ISBLK, 'a block device'))


class InputError(ValueError):
    """An input that is refused; one line. Attributes: detail, line (or None), file (or None)."""

    def __init__(self, detail, line=None, file=None):
        self.detail = ' '.join(str(detail).split())
        self.line = line
        self.file = None if file is None else str(file)
        if self.file is not None:
            text = f'{self.file}:{line}: {self.detail}' if line else f'{self.file}: {self.detail}'
        else:
            text = self.detail if line is None else f'line {line}: {self.detail}'
        super().__init__(text)


#: The name the route readers and the launcher have used for file errors.
TextFileError = InputError

_ROS_NAME = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')


def ros_name_problem(name):
    """None if ``name`` can be one token of a ROS name (a namespace, a topic's first part),
    else the one-line text of what is wrong with it."""
    if not isinstance(name, str):
        return f'a name must be text, got {name!r}'
    if not _ROS_NAME.fullmatch(name):
        return (f'{name!r} is not a ROS name: ASCII letters, digits and underscores only, not '
                'starting with a digit (like target_1)')
    return None


# -- files -----------------------------------------------------------------------------------------

def _check_mode(mode, path):
    if not stat.S_ISREG(mode):
        kind = next((k for test, k in _FILE_KINDS if test(mode)), 'not a regular file')
        raise InputError(f'it is {kind}, not a regular file', file=path)


def check_regular_file(path):
    """InputError unless ``path`` is a regular file (checked without opening it: opening a
    device may act, opening a FIFO blocks)."""
    try:
        _check_mode(os.stat(path).st_mode, path)
    except OSError as exc:
        raise InputError(exc.strerror, file=path) from None


def open_regular_file(path):
    """A binary file object of the regular file ``path``; InputError (one line) otherwise.

    The file is opened without blocking and checked on the open descriptor too (the name may
    have been swapped for a FIFO between the check and the open)."""
    check_regular_file(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, 'O_CLOEXEC', 0))
    except OSError as exc:
        raise InputError(exc.strerror, file=path) from None
    try:
        _check_mode(os.fstat(fd).st_mode, path)
        return os.fdopen(fd, 'rb')
    except BaseException:
        os.close(fd)
        raise


def read_regular_file(path, max_bytes=MAX_FILE_BYTES, binary=False):
    """The contents of the regular file ``path`` (UTF-8 text, or bytes with ``binary``);
    InputError (one line) for anything else: not a regular file, larger than ``max_bytes``,
    not UTF-8 (the line and byte offset given). ``file`` of the error is not set, so callers
    can name the file their own way; ``detail`` and ``line`` are the parts."""
    try:
        with open_regular_file(path) as f:
            data = f.read(max_bytes + 1)
    except InputError as exc:
        raise InputError(exc.detail) from None
    except OSError as exc:
        raise InputError(exc.strerror) from None
    if len(data) > max_bytes:
        raise InputError(f'it is larger than {max_bytes} bytes')
    if binary:
        return data
    try:
        return data.decode('utf-8')
    except UnicodeDecodeError as exc:
        line = data.count(b'\n', 0, exc.start) + 1
        raise InputError(f'not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})',
                         line=line) from None


#: The name the route readers have used.
read_text_file = read_regular_file


def _read(path, max_bytes):
    try:
        return read_regular_file(path, max_bytes)
    except InputError as exc:
        raise InputError(f'cannot read: {exc.detail}', line=exc.line, file=path) from None


# -- YAML ------------------------------------------------------------------------------------------

_NUMBER_TAGS = ('tag:yaml.org,2002:int', 'tag:yaml.org,2002:float')
_MERGE_TAG = 'tag:yaml.org,2002:merge'

try:        # libyaml's scanner and parser: the same events, a few times faster
    from yaml._yaml import CParser as _Parser
except ImportError:                                        # pragma: no cover (a pure PyYAML)
    from yaml.reader import Reader
    from yaml.scanner import Scanner
    from yaml.parser import Parser

    class _Parser(Reader, Scanner, Parser):
        def __init__(self, stream):
            Reader.__init__(self, stream)
            Scanner.__init__(self)
            Parser.__init__(self)


class Loader(yaml.composer.Composer, _Parser, yaml.constructor.SafeConstructor,
             yaml.resolver.Resolver):
    """yaml.SafeLoader's rules within the bounds of the module docstring (depth, values after
    alias expansion, number length, duplicate keys), checked while the document is composed (in
    Python: the composer is where the checks live; libyaml parses the events), and reading
    exponent numbers without a dot (``1e9``, ``-2E-3``) as floats, as YAML 1.2 does. A refusal
    raises InputError with the line (``file`` unset)."""

    def __init__(self, stream):
        _Parser.__init__(self, stream)
        yaml.composer.Composer.__init__(self)
        yaml.constructor.SafeConstructor.__init__(self)
        yaml.resolver.Resolver.__init__(self)
        self._depth = 0          # nesting of the node being composed
        self._deepest = 0        # deepest level reached so far (aliases expanded)
        self._count = 0          # values so far (aliases expanded)
        self._size = {}          # id(anchored node) -> (values, height) once composed

    def _refuse(self, detail, mark):
        raise InputError(detail, line=mark.line + 1 if mark is not None else None)

    def _add(self, n, mark):
        self._count += n
        if self._count > MAX_NODES:
            self._refuse(f'more than {MAX_NODES} values, counting what every alias stands for', mark)

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            node = self.anchors.get(event.anchor)
            if node is not None:
                if id(node) not in self._size:
                    self._refuse(f'the alias *{event.anchor} is inside its own anchor '
                                 '(a recursive structure)', event.start_mark)
                n, height = self._size[id(node)]
                self._add(n, event.start_mark)
                if self._depth + height > MAX_DEPTH:
                    self._refuse(f'nested deeper than {MAX_DEPTH} levels (aliases expanded)',
                                 event.start_mark)
                self._deepest = max(self._deepest, self._depth + height)
            return super().compose_node(parent, index)
        mark = self.peek_event().start_mark
        self._depth += 1
        if self._depth > MAX_DEPTH:
            self._refuse(f'nested deeper than {MAX_DEPTH} levels', mark)
        outer, start = self._deepest, self._count
        self._deepest = self._depth
        self._add(1, mark)
        node = super().compose_node(parent, index)
        height = self._deepest - self._depth + 1
        self._deepest = max(outer, self._deepest)
        self._depth -= 1
        if isinstance(node, yaml.ScalarNode) and node.tag in _NUMBER_TAGS \
                and len(node.value) > MAX_NUMBER_CHARS:
            self._refuse(f'a number of {len(node.value)} characters; at most '
                         f'{MAX_NUMBER_CHARS} are accepted', node.start_mark)
        self._size[id(node)] = (self._count - start, height)
        return node

    def compose_mapping_node(self, anchor):
        node = super().compose_mapping_node(anchor)
        seen = {}
        for key, _ in node.value:
            if not isinstance(key, yaml.ScalarNode) or key.tag == _MERGE_TAG:
                continue
            line = key.start_mark.line + 1
            first = seen.get((key.tag, key.value))
            if first is not None:
                self._refuse(f'key "{key.value}" is given twice, on lines {first} and {line}',
                             key.start_mark)
            seen[(key.tag, key.value)] = line
        return node


Loader.add_implicit_resolver('tag:yaml.org,2002:float',
                             re.compile(r'^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$'),
                             list('-+0123456789'))


def _yaml_error(exc, file):
    mark = getattr(exc, 'problem_mark', None)
    problem = getattr(exc, 'problem', None) or ' '.join(str(exc).split())
    return InputError(f'not valid YAML: {problem}', line=mark.line + 1 if mark else None,
                      file=file)


def compose_yaml(text, file=None):
    """The checked node tree of one YAML document (None for an empty one), for readers that
    want the lines of the values; InputError for anything beyond the bounds or not YAML."""
    loader = Loader(text)
    try:
        return loader.get_single_node()
    except InputError as exc:
        raise InputError(exc.detail, line=exc.line, file=file) from None
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, file) from None
    finally:
        _dispose(loader)


def load_yaml(text, file=None):
    """The data of one YAML document (safe types only); InputError (one line) otherwise."""
    loader = Loader(text)
    try:
        node = loader.get_single_node()
        return None if node is None else loader.construct_document(node)
    except InputError as exc:
        raise InputError(exc.detail, line=exc.line, file=file) from None
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, file) from None
    except (ValueError, OverflowError) as exc:   # a constructor's own refusal (e.g. a date)
        raise InputError(f'not valid YAML: {exc}', file=file) from None
    finally:
        _dispose(loader)


def _dispose(loader):
    dispose = getattr(loader, 'dispose', None)
    if dispose is not None:
        dispose()


def load_yaml_file(path, max_bytes=MAX_FILE_BYTES):
    """load_yaml of the regular file ``path``; InputError naming the file (and the line)."""
    return load_yaml(_read(path, max_bytes), file=path)


# -- JSON ------------------------------------------------------------------------------------------

_JSON_TOKENS = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}]')


def _json_depth(text, file):
    """Refuse nesting beyond MAX_DEPTH before json (a recursive parser) sees the text."""
    depth = 0
    for m in _JSON_TOKENS.finditer(text):
        c = m.group()
        if c in '[{':
            depth += 1
            if depth > MAX_DEPTH:
                line = text.count('\n', 0, m.start()) + 1
                raise InputError(f'nested deeper than {MAX_DEPTH} levels', line=line, file=file)
        elif c in ']}':
            depth -= 1


def _json_number(kind):
    def parse(s):
        if len(s) > MAX_NUMBER_CHARS:
            raise InputError(f'a number of {len(s)} characters; at most {MAX_NUMBER_CHARS} are '
                             'accepted')
        return kind(s)
    return parse


def _json_object(pairs):
    out = {}
    for key, value in pairs:
        if key in out:
            raise InputError(f'key "{key}" is given twice in one object')
        out[key] = value
    return out


def load_json(text, file=None):
    """The data of a JSON text within the bounds; InputError (one line) otherwise."""
    if isinstance(text, (bytes, bytearray)):
        try:
            text = text.decode('utf-8')
        except UnicodeDecodeError as exc:
            raise InputError(f'not UTF-8 text (offset {exc.start})', file=file) from None
    if len(text) > MAX_FILE_BYTES:
        raise InputError(f'it is larger than {MAX_FILE_BYTES} characters', file=file)
    _json_depth(text, file)
    try:
        return json.loads(text, parse_int=_json_number(int), parse_float=_json_number(float),
                          object_pairs_hook=_json_object)
    except InputError as exc:
        raise InputError(exc.detail, file=file) from None
    except json.JSONDecodeError as exc:
        raise InputError(f'not valid JSON: {exc.msg} (column {exc.colno})', line=exc.lineno,
                         file=file) from None
    except (RecursionError, ValueError) as exc:
        raise InputError(f'not valid JSON: {exc}', file=file) from None


def load_json_file(path, max_bytes=MAX_FILE_BYTES):
    """load_json of the regular file ``path``; InputError naming the file (and the line)."""
    return load_json(_read(path, max_bytes), file=path)
