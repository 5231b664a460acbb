"""host.receiver: the geometry and kind of a DMA stream learnt from a datagram (the one place
``radar receive`` and ``radar view`` learn it), and frames in float-reference units (the
chain gain divided out where the stream is decoded)."""

from __future__ import annotations

import numpy as np
import pytest

from host.capture import frame_packets
from host.receiver import CUBE, RECORDS, Receiver, chain_decoder
from model.config import PRESETS, get_preset
from model.radar_pipeline import PipelineParams, chain_gain

CFG = get_preset("paper-fpga")


def _cube(seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = CFG.cube_shape
    return (rng.integers(-200, 200, shape) + 1j * rng.integers(-200, 200, shape)).astype(
        np.complex64)


def _detect_config(cfg):  # noqa: ANN001, ANN202 - the board's default detector
    return PipelineParams(output_mode=1).detect_config(cfg)


def test_learnt_cube_stream_in_reference_units():
    """The first packet fixes preset and PACKET_WORDS; the decoded cube is the sent one
    divided by the chain gain."""
    cube = _cube()
    packets = frame_packets(cube, CFG, 1023, 7)
    rx = Receiver(list(PRESETS.values()), None, CUBE, _detect_config)
    dec = rx.learn(packets[0])
    assert (rx.cfg, rx.kind, dec.packet_words) == (CFG, CUBE, 1023)
    frames = [f for p in packets for f in dec.push_packet(p)]
    assert len(frames) == 1 and frames[0].complete
    gain = chain_gain(CFG, PipelineParams())
    np.testing.assert_array_equal(frames[0].cube(), cube / gain)


def test_kinds_are_named_not_guessed():
    """A cube packet given as records, or junk to a receiver learning the kind too, is
    refused with the reason; a record decoder's arrays carry the chain gain."""
    packet = frame_packets(_cube(), CFG, 1023, 0)[0]
    with pytest.raises(ValueError, match="radar-cube stream packet of paper-fpga"):
        Receiver([CFG], None, RECORDS, _detect_config).fit(packet)
    with pytest.raises(ValueError, match="fits no cube or record stream"):
        Receiver([CFG], None, None, _detect_config).fit(bytes(64))
    dec = chain_decoder(CFG, 256, PipelineParams(), _detect_config(CFG))
    assert dec.gain == chain_gain(CFG, PipelineParams())
