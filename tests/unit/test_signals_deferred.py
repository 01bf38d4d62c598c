"""A write that must not be cut in the middle (the checkpoint's np.savez) holds Ctrl-C and SIGTERM back until it is
done; they then end the run as they would have."""
from __future__ import annotations

import os
import signal
import time

import pytest

from ctmrpim.io.atomic import signals_deferred


def test_ctrl_c_inside_the_block_is_raised_after_it() -> None:
    # Python's own Ctrl-C handler, whatever this process inherited: a job started in the background by a
    # non-interactive shell begins with SIGINT ignored, and then Python installs none
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        done = []
        with pytest.raises(KeyboardInterrupt):
            with signals_deferred():
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.05)           # Python runs the (holding) handler here
                done.append(True)
        assert done == [True]
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler      # the handler is back
    finally:
        signal.signal(signal.SIGINT, previous)


def test_an_ignored_ctrl_c_stays_ignored() -> None:
    """Where SIGINT is ignored (a background job), a Ctrl-C inside the block is dropped, not raised."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, previous)


def test_sigterm_reaches_the_handler_that_was_set() -> None:
    seen = []
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: seen.append(signum))
    try:
        with signals_deferred():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)
            assert seen == []          # held back inside
        assert seen == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_a_quiet_block_changes_nothing() -> None:
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    with signals_deferred():
        pass
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
