"""The ``rinscope`` command of the Python package: the same command-line program, run by the
library inside this process (no Rust toolchain needed)."""
import signal
import sys

from . import _rinscope


def main() -> None:
    # The command answers Ctrl-C, SIGTERM and SIGHUP itself (it finishes the recording and exits
    # 128 + the signal); Python's own handlers would only raise after it returned.
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)
    sys.stdout.flush()
    sys.exit(_rinscope.cli(["rinscope", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
