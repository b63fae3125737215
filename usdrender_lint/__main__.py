"""``python -m usdrender_lint`` and the ``usdrender-lint`` command.

Ctrl-C and SIGTERM are handled from the moment this module is imported,
before the command line's own imports (click, the engine): a signal during
them exits 130 or 143 with one line, like one during the run.
"""

import os
import sys

from .running import address_space, interrupts, supervisor

interrupts.install()


def main() -> None:
    supervision = None
    supervisor.open_closed_standard_fds()
    try:
        if supervisor.wants_supervision(sys.argv[1:]):
            # The child, or this process after the child's crash or time-out.
            supervision = supervisor.supervise(supervisor.reads_standard_input(sys.argv[1:]))
        from .cli import main as command
    except interrupts.Stopped as stopped:
        sys.stderr.write(f"usdrender-lint: {stopped.reason}\n")
        sys.exit(stopped.exit_status)
    except (MemoryError, ImportError) as exc:  # click or the command line, under ulimit -v
        try:
            said = address_space.out_of_memory_at_start(exc)
        except MemoryError:  # not even the limit could be read
            said = "out of memory while starting: raise the memory limit (ulimit -v)"
        if said is None:
            raise
        sys.stderr.write(f"usdrender-lint: error: {said}\n")
        sys.exit(2)
    try:
        command(supervision=supervision)
    except MemoryError:
        # The command's own handlers ran out of memory too (ulimit -v): bytes
        # made before, written without allocating a message.
        os.write(2, _OUT_OF_MEMORY)
        sys.exit(2)


_OUT_OF_MEMORY = b"usdrender-lint: error: out of memory: raise the memory limit (ulimit -v)\n"


if __name__ == "__main__":
    main()
