"""Reading an input file as text without ever blocking: the one check every file input uses.

Route files, scenarios and AIS replay files are read only if they are regular files: a FIFO, a
directory, a socket or a device is refused before it is read (a FIFO without a writer would
block the reader forever, /dev/zero would never end), and so is a file over a size bound.
"""
import os
import stat

#: Largest input file (bytes) read as a route or scenario file (callers may give their own).
MAX_FILE_BYTES = 10_000_000

_FILE_KINDS = ((stat.S_ISDIR, 'a directory'), (stat.S_ISFIFO, 'a FIFO (named pipe)'),
               (stat.S_ISSOCK, 'a socket'), (stat.S_ISCHR, 'a character device'),
               (stat.S_ISBLK, 'a block device'))


class TextFileError(ValueError):
    """A file that cannot be read as text (read_text_file); ``detail`` and ``line`` (or None)."""

    def __init__(self, detail, line=None):
        self.detail = detail
        self.line = line
        super().__init__(detail if line is None else f'line {line}: {detail}')


def _check_regular(mode):
    if not stat.S_ISREG(mode):
        kind = next((k for test, k in _FILE_KINDS if test(mode)), 'not a regular file')
        raise TextFileError(f'it is {kind}, not a regular file')


def read_text_file(path, max_bytes=MAX_FILE_BYTES, encoding='utf-8', errors='strict'):
    """The text of the regular file ``path``; TextFileError (one line) otherwise.

    The file is opened without blocking and checked on the open descriptor, so a FIFO, a
    directory or a device is refused without waiting for a writer; a file over ``max_bytes``
    or, with ``errors='strict'``, with bytes that are not ``encoding`` (line and byte offset
    given) is refused too."""
    try:
        _check_regular(os.stat(path).st_mode)     # before opening: opening a device may act
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, 'O_CLOEXEC', 0))
    except OSError as exc:
        raise TextFileError(exc.strerror) from None
    try:
        _check_regular(os.fstat(fd).st_mode)      # and what was opened (it may have been swapped)
        with os.fdopen(fd, 'rb', closefd=False) as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise TextFileError(exc.strerror) from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise TextFileError(f'it is larger than {max_bytes} bytes')
    try:
        return data.decode(encoding, errors)
    except UnicodeDecodeError as exc:
        line = data.count(b'\n', 0, exc.start) + 1
        name = 'UTF-8' if encoding.replace('-', '').lower() == 'utf8' else encoding
        raise TextFileError(f'not {name} text (byte 0x{data[exc.start]:02x} at offset '
                            f'{exc.start})', line=line) from None
