"""Link budget of the detection records (OUTPUT_MODE = 1) against the cube (mode 0): bytes per
frame and Mbit/s at the radar's frame rate, with the axis_packetizer header and CRC words.

Usage: python tb/detect_chain/bench_detect_link.py [--fps 111] [--packet-words 256]
Prints a table; the record layout comes from model/detect_records.py.
"""

from __future__ import annotations

import argparse

import numpy as np

from model import detect_records as dr
from model.axis_packetizer import packetize, words_to_bytes
from model.config import PRESETS


def link_bytes(words: int, num_rx: int, packet_words: int) -> int:
    """Bytes on the link for ``words`` payload words cut into packets as the RTL sends them
    (``model.axis_packetizer.packetize``: a header word, the payload, a CRC word each)."""
    return sum(len(words_to_bytes(p)) for p in packetize(
        np.zeros((words, num_rx), np.uint32), packet_words))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fps", type=float, default=111.0, help="frames per second (paper: 111)")
    ap.add_argument("--packet-words", type=int, default=256, help="axis_packetizer PACKET_WORDS")
    args = ap.parse_args()
    print(f"| preset | payload | detections | MAX_DETECTIONS | bytes/frame | Mbit/s at "
          f"{args.fps:g} fps |")
    print("|---|---|---|---|---|---|")
    for name in ("paper-fpga", "full"):
        cfg = PRESETS[name]
        tx, rx = cfg.num_tx, cfg.num_rx
        cube = link_bytes(tx * cfg.n_range * cfg.n_doppler, rx, args.packet_words)
        print(f"| {name} | radar cube (mode 0) | - | - | {cube} | "
              f"{cube * 8 * args.fps / 1e6:.1f} |")
        for n in (10, 100, 1000):
            fixed = link_bytes(dr.frame_words(tx, rx, n), rx, args.packet_words)
            print(f"| {name} | records, frame padded to MAX (RTL today) | <= {n} | {n} | "
                  f"{fixed} | {fixed * 8 * args.fps / 1e6:.1f} |")


if __name__ == "__main__":
    main()
