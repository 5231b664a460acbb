"""The packet CRC's single source (model/packet_crc.py): the generated RTL module is up to
date, and the parallel update it implements (one NUM_RX x 32-bit word per clock) equals
CRC-32 (zlib) of the wire bytes for every lane count."""

import zlib

import numpy as np
import pytest

from model.packet_crc import CRC_INIT, MAX_LANES, lane_rows, packet_crc, stale, word_update


def test_generated_module_up_to_date() -> None:
    """rtl/buffers/packet_crc32.sv is exactly what model/packet_crc.py renders."""
    assert not stale(), "stale: run `make gen`"


@pytest.mark.parametrize("lanes", [1, 2, 3, 4, 16, MAX_LANES])
def test_parallel_update_is_crc32_of_the_wire_bytes(lanes: int) -> None:
    rows = lane_rows()
    rng = np.random.default_rng(lanes)
    for n_words in (1, 2, 7):
        words = rng.integers(0, 1 << 32, (n_words, lanes), dtype=np.uint32)
        state = CRC_INIT
        for w in words:
            state = word_update(state, w, rows)
        wire = words.astype("<u4").tobytes()
        assert state ^ CRC_INIT == packet_crc(wire) == zlib.crc32(wire)


def test_known_value() -> None:
    """CRC-32 check value of b"123456789" (IEEE 802.3, zlib, PNG)."""
    assert packet_crc(b"123456789") == 0xCBF43926
