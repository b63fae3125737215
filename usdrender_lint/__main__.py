"""``python -m usdrender_lint`` and the ``usdrender-lint`` command.

Ctrl-C and SIGTERM are handled from the moment this module is imported,
before the command line's own imports (click, the engine): a signal during
them exits 130 or 143 with one line, like one during the run.
"""

import sys

from .running import interrupts, supervisor

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
    command(supervision=supervision)


if __name__ == "__main__":
    main()
