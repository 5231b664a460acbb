"""Cycle-accurate model of ``rtl/buffers/mark_fifo.sv``: a small FIFO of per-frame marks.

One :meth:`MarkFifo.step` is one rising clock edge. The outputs (:attr:`head`, :attr:`empty`,
:attr:`full`, :attr:`count`, :attr:`overflow`, :attr:`underflow`) are those the RTL shows
between edges, so a testbench samples them before the edge and compares.
"""

from __future__ import annotations

from collections import deque


class MarkFifo:
    """``depth`` marks of ``width`` bits (ints in ``0 .. 2**width - 1``)."""

    def __init__(self, depth: int = 4, width: int = 1) -> None:
        if not 2 <= depth <= 64:
            raise ValueError(f"mark_fifo: depth={depth} must be in 2..64")
        if not 1 <= width <= 64:
            raise ValueError(f"mark_fifo: width={width} must be in 1..64")
        self.depth, self.width = depth, width
        self.reset()

    def reset(self) -> None:
        """Synchronous reset: empty queue, flags cleared."""
        self.q: deque[int] = deque()
        self.overflow = False
        self.underflow = False

    @property
    def count(self) -> int:
        return len(self.q)

    @property
    def empty(self) -> bool:
        return not self.q

    @property
    def full(self) -> bool:
        return len(self.q) == self.depth

    @property
    def head(self) -> int:
        """Oldest mark, 0 when empty."""
        return self.q[0] if self.q else 0

    def step(self, push: bool, data: int, pop: bool, rst: bool = False) -> None:
        """One clock edge: reset, or pop (if not empty) then push (if not full, or popping).
        A refused push sets the sticky ``overflow``, a pop of an empty queue ``underflow``."""
        if rst:
            self.reset()
            return
        do_pop = pop and not self.empty
        do_push = push and (not self.full or do_pop)
        self.overflow |= push and not do_push
        self.underflow |= pop and self.empty
        if do_pop:
            self.q.popleft()
        if do_push:
            self.q.append(data & ((1 << self.width) - 1))
