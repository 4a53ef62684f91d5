"""OpenCV's thread pool, held to the calling thread for calls on tiny images."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import cv2


@contextlib.contextmanager
def serial_opencv() -> Iterator[None]:
    """OpenCV runs its calls in the calling thread within the block (the process's setting
    is put back after).

    For a blob's window of a few hundred pixels, handing stripes to the pool costs more
    CPU than the call: its threads spin on after each one.  Lockstep's detection over a
    stack holds it once per stack (``benchmarks/batch_env.py``, 16 and 64 heads: 8-28 %
    more head-steps per CPU-second, the same per wall-second).  Not for the classic path:
    there the pool's threads, kept warm, make the frames' remap and noise faster by the
    wall clock, and holding it per window cost 7-15 % of wall time.  The pixels are the
    same: each call's rows are computed alike, however they are shared out.
    """
    threads = cv2.getNumThreads()
    if threads <= 1:
        yield
        return
    cv2.setNumThreads(1)
    try:
        yield
    finally:
        cv2.setNumThreads(threads)


__all__ = ["serial_opencv"]
