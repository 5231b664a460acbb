"""Bit-accurate model of ``rtl/regs/radar_ctrl.sv``: the register file as software sees it.

The state changes in two ways, as in the RTL: a completed AXI4-Lite access (:meth:`write`,
:meth:`read`; byte address, 32-bit data, byte strobes) and one clock edge with its event
pulses (:meth:`step`). Rules (docs/regs.md): settings writes are checked whole after the byte
strobes are merged and refused whole when a field is out of range (CFG_ERRORS + 1,
STATUS.cfg_error); the pending settings become the active ones at the edge after a
``frame_start`` pulse; counters saturate at 2**32 - 1; STATUS flags are sticky and cleared by
writing 1; ``irq`` is registered: after an edge it is the OR of (STATUS & IRQ_ENABLE) as it
was before that edge. Register addresses and fields come from the generated
``model.radar_regs_map``.
"""

from __future__ import annotations

from dataclasses import dataclass

from model.radar_regs_map import REGISTERS, Register

MASK32 = 0xFFFF_FFFF
SETTINGS_REGS = ("SETTINGS", "CFAR_SCALE", "PACKET")
"""The software-written settings, as (pending) registers; ACTIVE_<name> reads the active set."""
COUNTERS = {"frame_done": "FRAMES", "packet_done": "PACKETS", "drop": "DROPS",
            "error": "ERRORS"}
"""Event pulse -> the counter it increments (cfg_error increments CFG_ERRORS)."""
FLAGS = ("frame_done", "drop", "error", "cfg_error")
"""STATUS / IRQ_ENABLE bits, in bit order."""
CFAR_KINDS = (0, 1)
"""Legal SETTINGS.cfar_kind values (0 = cell averaging, 1 = ordered statistic)."""


def _get(reg: Register, value: int, name: str) -> int:
    f = next(f for f in reg.fields if f.name == name)
    return (value >> f.lsb) & ((1 << f.width) - 1)


def _mask(reg: Register) -> int:
    """Bits of ``reg`` that hold a field."""
    m = 0
    for f in reg.fields:
        m |= ((1 << f.width) - 1) << f.lsb
    return m


@dataclass
class RadarCtrl:
    """Register state of one ``radar_ctrl`` instance with its HDL parameters."""

    max_detections: int = 256
    packet_words: int = 1024
    cfar_kind: int = 0
    cfar_scale: int = 0
    clutter_removal: bool = False

    def __post_init__(self) -> None:
        for name, value, lo, hi in (("MAX_DETECTIONS", self.max_detections, 1, 65535),
                                    ("PACKET_WORDS", self.packet_words, 1, 65535),
                                    ("CFAR_KIND", self.cfar_kind, 0, 1)):
            if not lo <= value <= hi:
                raise ValueError(f"{name}={value} must be {lo}..{hi}")
        self.reset()

    # ---- state -------------------------------------------------------------------------
    def reset(self) -> None:
        """``rst``: settings to the parameters' values, flags, enables, counters and irq 0."""
        settings = (self.cfar_kind | (int(self.clutter_removal) << 4)
                    | (self.max_detections << 16))
        self.pending = {"SETTINGS": settings, "CFAR_SCALE": self.cfar_scale & MASK32,
                        "PACKET": self.packet_words}
        self.active = dict(self.pending)
        self.status = 0
        self.irq_enable = 0
        self.counts = {name: 0 for name in (*COUNTERS.values(), "CFG_ERRORS")}
        self.irq = False

    def legal(self, name: str, value: int) -> bool:
        """Whether ``value`` (the whole register after the write) may be held by ``name``."""
        reg = REGISTERS[name]
        if name == "SETTINGS":
            md = _get(reg, value, "max_detections")
            return _get(reg, value, "cfar_kind") in CFAR_KINDS and 1 <= md <= self.max_detections
        if name == "PACKET":
            return 1 <= _get(reg, value, "words") <= self.packet_words
        return True

    def _count(self, name: str) -> None:
        self.counts[name] = min(self.counts[name] + 1, MASK32)

    # ---- bus ---------------------------------------------------------------------------
    def write(self, address: int, data: int, strb: int = 0xF) -> None:
        """One completed AXI4-Lite write (OKAY response; writes to read-only or unmapped
        addresses change nothing)."""
        bits = 0
        for lane in range(4):
            if strb >> lane & 1:
                bits |= 0xFF << (8 * lane)
        name = self.name_at(address)
        if name is None:
            return
        if name in SETTINGS_REGS:
            m = bits & _mask(REGISTERS[name])
            new = (self.pending[name] & ~m) | (data & m)
            if self.legal(name, new):
                self.pending[name] = new
            else:
                self._count("CFG_ERRORS")
                self.status |= 1 << FLAGS.index("cfg_error")
        elif name == "STATUS":
            self.status &= ~(data & bits) & 0xF
        elif name == "IRQ_ENABLE":
            self.irq_enable = (self.irq_enable & ~bits | data & bits) & 0xF

    def read(self, address: int) -> int:
        """One AXI4-Lite read: the register's value (0 at an unmapped address)."""
        name = self.name_at(address)
        if name is None:
            return 0
        if name in SETTINGS_REGS:
            return self.pending[name]
        if name.startswith("ACTIVE_"):
            return self.active[name.removeprefix("ACTIVE_")]
        if name in self.counts:
            return self.counts[name]
        fixed = {"STATUS": self.status, "IRQ_ENABLE": self.irq_enable,
                 "CAPS": self.max_detections | (self.packet_words << 16)}
        if name in fixed:
            return fixed[name]
        reg = REGISTERS[name]
        return sum((f.reset or 0) << f.lsb for f in reg.fields)

    @staticmethod
    def name_at(address: int) -> str | None:
        """The register at byte ``address`` (the low two bits ignored), None if unmapped."""
        for name, reg in REGISTERS.items():
            if reg.address == address & ~3:
                return name
        return None

    # ---- clock -------------------------------------------------------------------------
    def step(self, frame_start: bool = False, frame_done: bool = False,
             packet_done: bool = False, drop: bool = False, error: bool = False) -> None:
        """One rising clock edge with these event pulses high in the cycle before it."""
        self.irq = bool(self.status & self.irq_enable)
        if frame_start:
            self.active = dict(self.pending)
        events = {"frame_done": frame_done, "packet_done": packet_done, "drop": drop,
                  "error": error}
        for event, counter in COUNTERS.items():
            if events[event]:
                self._count(counter)
                if event in FLAGS:
                    self.status |= 1 << FLAGS.index(event)

    def active_fields(self) -> dict[str, int]:
        """The cfg_* outputs: cfar_kind, clutter_removal, max_detections, cfar_scale,
        packet_words."""
        s = REGISTERS["SETTINGS"]
        a = self.active["SETTINGS"]
        return {"cfar_kind": _get(s, a, "cfar_kind"),
                "clutter_removal": _get(s, a, "clutter_removal"),
                "max_detections": _get(s, a, "max_detections"),
                "cfar_scale": self.active["CFAR_SCALE"],
                "packet_words": _get(REGISTERS["PACKET"], self.active["PACKET"], "words")}
