"""Starting under an address-space limit (``ulimit -v``, RLIMIT_AS) too small to
load USD: one line and exit 2, never USD's own tracebacks or a crash.

Nothing is imported but ``resource``: the command asks before its own imports.
"""

from __future__ import annotations

#: typing's own flag, without importing typing (and re, contextlib...): this
#: module is imported before the supervisor forks (__main__.py), and what the
#: supervisor imports it also tears down, after the command has ended.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from ..engine import SchemasMissing

#: Below this limit usd-core cannot be loaded at all: its libraries map about
#: 580 MiB of address space as they load (usd-core 26.11, Linux x86-64, measured
#: with ``ulimit -v``), and between about 100 and 500 MiB the import crashes
#: (SIGSEGV) after USD printed Python tracebacks of its own (TfScriptModuleLoader).
FLOOR = 512 * 2**20

#: How a failed import says it found no memory (glibc's dlopen; errno ENOMEM).
_NO_MEMORY = ("failed to map segment", "Cannot allocate memory")


def address_space_limit() -> int | None:
    """The process's soft address-space limit in bytes; None when unlimited."""
    try:
        import resource
    except ImportError:  # not POSIX
        return None
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    return None if soft == resource.RLIM_INFINITY else soft


def refusal() -> str | None:
    """Why the command cannot load USD under the limit set, or None."""
    limit = address_space_limit()
    if limit is None or limit >= FLOOR:
        return None
    return _message(limit)


def out_of_memory_at_start(exc: BaseException) -> str | None:
    """The error for an import that failed for want of memory; None for another failure."""
    if isinstance(exc, MemoryError) or (
        isinstance(exc, (ImportError, OSError)) and any(s in str(exc) for s in _NO_MEMORY)
    ):
        return out_of_memory()
    return None


def out_of_memory() -> str:
    """The out-of-memory line, naming the address-space limit where one is set."""
    return _message(address_space_limit())


def limit_hint() -> str:
    """What to add to a failure that a tight address-space limit may have caused
    (USD starts between about 512 MiB and 1 GiB, then fails as it loads more):
    "" when no limit is set."""
    limit = address_space_limit()
    if limit is None:
        return ""
    return f"; the address-space limit (ulimit -v) is {limit // 2**20} MiB: raise it"


def schemas_missing(exc: SchemasMissing) -> str:
    """The run's error when USD's schema registry lacks the rules' schemas: under
    ``ulimit -v`` about 1.1 GiB it failed to read them for want of memory."""
    return str(exc) if exc.disabled else f"{exc}{limit_hint()}"


def _message(limit: int | None) -> str:
    if limit is None:
        return "out of memory while loading USD: raise the memory limit (ulimit -v) or free memory"
    if limit >= FLOOR:  # USD loaded, and ran out later
        return f"out of memory: the address-space limit (ulimit -v) is {limit >> 20} MiB: raise it"
    return (
        f"out of memory: the address-space limit (ulimit -v) is {limit // 2**20} MiB, too small "
        "to load USD (it maps about 600 MiB as it loads): raise it"
    )
