"""Bit-accurate model of ``rtl/regs/radar_ctrl.sv``: the register file as software sees it.

The state changes in two ways, as in the RTL: a completed AXI4-Lite access (:meth:`write`,
:meth:`read`; byte address, 32-bit data, byte strobes) and one clock edge with its event
pulses (:meth:`step`). Rules (docs/regs.md): settings writes are checked whole after the byte
strobes are merged and refused whole when a field is out of range (CFG_ERRORS + 1,
STATUS.cfg_error); the pending settings of each consumer become active at the edge after that
consumer's frame-start pulse (:data:`GROUPS`); counters saturate at 2**32 - 1; STATUS flags
are sticky and cleared by writing 1; ``irq`` is registered: after an edge it is the OR of
(STATUS & IRQ_ENABLE) as it was before that edge. Register addresses and fields come from the
generated ``model.radar_regs_map``.
"""

from __future__ import annotations

from dataclasses import dataclass

from model.radar_regs_map import REGISTERS, Field, Register

MASK32 = 0xFFFF_FFFF
SETTINGS_REGS = ("SETTINGS", "PACKET", "CFAR_SCALE")
"""The software-written settings, as (pending) registers; ACTIVE_<name> reads the active set."""
GROUPS = {"removal_start": (("SETTINGS", "clutter_removal"),),
          "detect_start": (("SETTINGS", "cfar_kind"), ("SETTINGS", "local_max"),
                           ("SETTINGS", "max_detections"), ("CFAR_SCALE", "scale")),
          "packet_start": (("PACKET", "words"),)}
"""Frame-start pulse of each consumer -> the (register, field)s it makes active."""
COUNTERS = {"frame_done": "FRAMES", "packet_done": "PACKETS", "drop": "DROPS",
            "error": "ERRORS"}
"""Event pulse -> the counter it increments (cfg_error increments CFG_ERRORS)."""
FLAGS = ("frame_done", "drop", "error", "cfg_error")
"""STATUS / IRQ_ENABLE bits, in bit order."""
CFAR_KIND_CODES = {"ca": 0, "go": 1, "so": 2, "os": 3}
"""SETTINGS.cfar_kind code of each CFAR kind (the detector's codes)."""


def _get(reg: Register, value: int, name: str) -> int:
    f = next(f for f in reg.fields if f.name == name)
    return (value >> f.lsb) & ((1 << f.width) - 1)


def _field_mask(f: Field) -> int:
    """Bits of field ``f`` in its register."""
    return ((1 << f.width) - 1) << f.lsb


def _mask(reg: Register) -> int:
    """Bits of ``reg`` that hold a field."""
    return sum(_field_mask(f) for f in reg.fields)


@dataclass
class RadarCtrl:
    """Register state of one ``radar_ctrl`` instance with its HDL parameters (same names in
    lower case; ``cfar_kinds``: bit k set when CFAR kind k is built in)."""

    max_detections: int = 256
    packet_words: int = 1024
    cfar_kind: int = 0
    cfar_scale: int = 0
    clutter_removal: bool = False
    packet_words_min: int = 1
    cfar_kinds: int = 0b0111
    n_scales: int = 13
    scale_w: int = 32
    local_max: bool = False

    def __post_init__(self) -> None:
        n_sc = REGISTERS["CFAR_SCALE"].count
        for name, value, lo, hi in (("MAX_DETECTIONS", self.max_detections, 1, 65535),
                                    ("PACKET_WORDS", self.packet_words, 1, 65535),
                                    ("PACKET_WORDS_MIN", self.packet_words_min, 1,
                                     self.packet_words),
                                    ("CFAR_KINDS", self.cfar_kinds, 1, 15),
                                    ("CFAR_KIND", self.cfar_kind, 0, 3),
                                    ("N_SCALES", self.n_scales, 1, n_sc),
                                    ("SCALE_W", self.scale_w, 1, 32),
                                    ("CFAR_SCALE", self.cfar_scale, 0,
                                     (1 << self.scale_w) - 1)):
            if not lo <= value <= hi:
                raise ValueError(f"{name}={value} must be {lo}..{hi}")
        if not self.cfar_kinds >> self.cfar_kind & 1:
            raise ValueError(f"CFAR_KIND={self.cfar_kind} is not built in "
                             f"(CFAR_KINDS={self.cfar_kinds})")
        self.reset()

    # ---- state -------------------------------------------------------------------------
    def reset(self) -> None:
        """``rst``: settings to the parameters' values, flags, enables, counters and irq 0."""
        settings = (self.cfar_kind | (int(self.clutter_removal) << 4)
                    | (int(self.local_max) << 5) | (self.max_detections << 16))
        self.pending: dict[str, int] = {"SETTINGS": settings, "PACKET": self.packet_words}
        self.pending_scale = [self.cfar_scale] * self.n_scales
        self.active = dict(self.pending)
        self.active_scale = list(self.pending_scale)
        self.status = 0
        self.irq_enable = 0
        self.counts = {name: 0 for name in (*COUNTERS.values(), "CFG_ERRORS")}
        self.irq = False

    def legal(self, name: str, value: int, index: int = 0) -> bool:
        """Whether ``value`` (the whole register after the write) may be held by entry
        ``index`` of ``name``."""
        reg = REGISTERS[name]
        if name == "SETTINGS":
            md = _get(reg, value, "max_detections")
            return bool(self.cfar_kinds >> _get(reg, value, "cfar_kind") & 1
                        and 1 <= md <= self.max_detections)
        if name == "PACKET":
            return self.packet_words_min <= _get(reg, value, "words") <= self.packet_words
        if name == "CFAR_SCALE":
            return index < self.n_scales and value < 1 << self.scale_w
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
        at = self.name_at(address)
        if at is None:
            return
        name, index = at
        if name in SETTINGS_REGS:
            m = bits & _mask(REGISTERS[name])
            old = (self.pending_scale[index] if index < self.n_scales else 0) \
                if name == "CFAR_SCALE" else self.pending[name]
            new = (old & ~m) | (data & m)
            if not self.legal(name, new, index):
                self._count("CFG_ERRORS")
                self.status |= 1 << FLAGS.index("cfg_error")
            elif name == "CFAR_SCALE":
                self.pending_scale[index] = new
            else:
                self.pending[name] = new
        elif name == "STATUS":
            self.status &= ~(data & bits) & 0xF
        elif name == "IRQ_ENABLE":
            self.irq_enable = (self.irq_enable & ~bits | data & bits) & 0xF

    def read(self, address: int) -> int:
        """One AXI4-Lite read: the register's value (0 at an unmapped address)."""
        at = self.name_at(address)
        if at is None:
            return 0
        name, index = at
        if name in ("CFAR_SCALE", "ACTIVE_CFAR_SCALE"):
            table = self.pending_scale if name == "CFAR_SCALE" else self.active_scale
            return table[index] if index < self.n_scales else 0
        if name in SETTINGS_REGS:
            return self.pending[name]
        if name.startswith("ACTIVE_"):
            return self.active[name.removeprefix("ACTIVE_")]
        if name in self.counts:
            return self.counts[name]
        fixed = {"STATUS": self.status, "IRQ_ENABLE": self.irq_enable,
                 "CAPS": self.max_detections | (self.packet_words << 16),
                 "CAPS2": self.cfar_kinds | (self.n_scales << 8)
                 | (self.packet_words_min << 16)}
        if name in fixed:
            return fixed[name]
        reg = REGISTERS[name]
        return sum((f.reset or 0) << f.lsb for f in reg.fields)

    @staticmethod
    def name_at(address: int) -> tuple[str, int] | None:
        """The register and array entry at byte ``address`` (the low two bits ignored), None
        if unmapped."""
        a = address & ~3
        for name, reg in REGISTERS.items():
            if reg.address <= a < reg.address + reg.count * reg.stride \
                    and (a - reg.address) % reg.stride == 0:
                return name, (a - reg.address) // reg.stride
        return None

    # ---- clock -------------------------------------------------------------------------
    def step(self, removal_start: bool = False, detect_start: bool = False,
             packet_start: bool = False, frame_done: bool = False,
             packet_done: bool = False, drop: bool = False, error: bool = False) -> None:
        """One rising clock edge with these event pulses high in the cycle before it."""
        self.irq = bool(self.status & self.irq_enable)
        starts = {"removal_start": removal_start, "detect_start": detect_start,
                  "packet_start": packet_start}
        for start, fields in GROUPS.items():
            if not starts[start]:
                continue
            for name in ("SETTINGS", "PACKET"):
                m = sum(_field_mask(f) for f in REGISTERS[name].fields
                        if (name, f.name) in fields)
                self.active[name] = (self.active[name] & ~m) | (self.pending[name] & m)
            if ("CFAR_SCALE", "scale") in fields:
                self.active_scale = list(self.pending_scale)
        events = {"frame_done": frame_done, "packet_done": packet_done, "drop": drop,
                  "error": error}
        for event, counter in COUNTERS.items():
            if events[event]:
                self._count(counter)
                if event in FLAGS:
                    self.status |= 1 << FLAGS.index(event)

    def pend_packet_words(self) -> int:
        """The ``pend_packet_words`` output: the pending ``PACKET.words``, what
        ``cfg_packet_words`` becomes at the edge after a ``packet_start`` cycle (the top's
        packetizer takes it with a frame's first word, in such a cycle)."""
        return _get(REGISTERS["PACKET"], self.pending["PACKET"], "words")

    def active_fields(self) -> dict[str, int]:
        """The cfg_* outputs: cfar_kind, local_max, clutter_removal, max_detections,
        packet_words, cfar_scale (the packed table, entry e at bits e * scale_w)."""
        s = REGISTERS["SETTINGS"]
        a = self.active["SETTINGS"]
        return {"cfar_kind": _get(s, a, "cfar_kind"),
                "local_max": _get(s, a, "local_max"),
                "clutter_removal": _get(s, a, "clutter_removal"),
                "max_detections": _get(s, a, "max_detections"),
                "packet_words": _get(REGISTERS["PACKET"], self.active["PACKET"], "words"),
                "cfar_scale": sum(v << (e * self.scale_w)
                                  for e, v in enumerate(self.active_scale))}
