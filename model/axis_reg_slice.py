"""Cycle-accurate model of ``rtl/common/axis_reg_slice.sv``: an AXI4-Stream register slice.

The slice is a FIFO of two words whose outputs all come from registers: the output register
and a skid register that catches the beat accepted in the clock the sink stalls. Its beat
sequence is the input's, one clock later at the earliest (:data:`LATENCY`), at full rate.

One :meth:`AxisRegSlice.step` is one rising clock edge. :attr:`s_ready`, :attr:`m_valid` and
:attr:`m_word` are what the RTL shows between edges (``s_ready`` as if ``rst`` is low: the
RTL also holds TREADY low while ``rst`` is high). A word is any Python value (the testbench
passes ``(tdata, tlast, tuser)`` tuples).
"""

from __future__ import annotations

from typing import Any

LATENCY = 1
"""Clocks from an input beat to the same word on the output, the sink ready (docs/buffers.md 9)."""


class AxisRegSlice:
    """Output register and skid register, each with its valid bit; both empty after reset."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Synchronous reset: both registers empty (their words are not reset in the RTL)."""
        self.out: Any = None
        self.skid: Any = None
        self.out_valid = False
        self.skid_valid = False

    @property
    def s_ready(self) -> bool:
        """TREADY: the skid register is empty."""
        return not self.skid_valid

    @property
    def m_valid(self) -> bool:
        return self.out_valid

    @property
    def m_word(self) -> Any:
        """The output word (meaningful while :attr:`m_valid`)."""
        return self.out

    def step(self, s_valid: bool, s_word: Any, m_ready: bool, rst: bool = False) -> None:
        """One clock edge with these input levels: reset, or the output register takes the
        skid's word, else the input beat, when it is empty or its word leaves; otherwise an
        input beat goes to the skid register."""
        if rst:
            self.reset()
            return
        in_beat = s_valid and self.s_ready
        if not self.out_valid or m_ready:
            if self.skid_valid:
                self.out, self.out_valid = self.skid, True
            else:
                self.out_valid = in_beat
                if in_beat:
                    self.out = s_word
            self.skid_valid = False
        elif in_beat:
            self.skid, self.skid_valid = s_word, True
