"""The register map (rtl/regs/radar_regs.rdl): generated files current, the C header compiles
with the offsets the Python map states, the access layer host.regs over the model
model/radar_ctrl.py (the RTL side is tb/radar_ctrl)."""

from __future__ import annotations

import filecmp
import importlib.util
import shutil
import subprocess
from pathlib import Path

import pytest

from host import regs
from model.radar_ctrl import MASK32, RadarCtrl
from model.radar_regs_map import REGISTERS

REPO = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("gen_regs", REPO / "tools" / "gen_regs.py")
gen_regs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(gen_regs)


def test_generated_files_up_to_date(tmp_path: Path) -> None:
    """Every file tools/gen_regs.py writes is committed exactly as it writes it."""
    written = gen_regs.generate(tmp_path)
    stale = [str(p.relative_to(tmp_path)) for p in written
             if not filecmp.cmp(p, REPO / p.relative_to(tmp_path), shallow=False)]
    assert not stale, f"stale: run `make regs`: {stale}"
    html = {p.relative_to(tmp_path) for p in written
            if gen_regs.HTML_DIR in p.relative_to(tmp_path).parents}
    have = {p.relative_to(REPO) for p in (REPO / gen_regs.HTML_DIR).rglob("*") if p.is_file()}
    assert have == html, f"docs/regs/html: extra {have - html}, missing {html - have}"


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc")
def test_c_header_compiles_with_the_maps_offsets(tmp_path: Path) -> None:
    checks = "\n".join(
        f"_Static_assert(offsetof(radar_regs_t, {name}) == {reg.address:#x}, \"{name}\");"
        for name, reg in REGISTERS.items())
    src = tmp_path / "t.c"
    src.write_text(f'#include <stddef.h>\n#include "radar_regs.h"\n{checks}\n'
                   "int main(void) { return RADAR_REGS__SETTINGS__MAX_DETECTIONS_bp != 16; }\n")
    r = subprocess.run(["gcc", "-std=gnu11", "-Wall", "-Werror", "-I",
                        str(REPO / "sw" / "include"), "-o", str(tmp_path / "t"), str(src)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert subprocess.run([str(tmp_path / "t")]).returncode == 0


def test_encode_decode() -> None:
    word = regs.encode("SETTINGS", cfar_kind=1, clutter_removal=1, max_detections=300)
    assert word == 1 | 1 << 4 | 300 << 16
    assert regs.decode("SETTINGS", word) == {"cfar_kind": 1, "clutter_removal": 1,
                                             "local_max": 0, "max_detections": 300}
    assert regs.address("STATUS") == 0x30
    assert regs.address("CFAR_SCALE", 2) == regs.address("CFAR_SCALE") + 8
    with pytest.raises(IndexError):
        regs.address("CFAR_SCALE", REGISTERS["CFAR_SCALE"].count)
    with pytest.raises(ValueError, match="no field"):
        regs.encode("SETTINGS", kind=1)
    with pytest.raises(ValueError, match="does not fit"):
        regs.encode("SETTINGS", max_detections=1 << 16)
    with pytest.raises(KeyError, match="no register"):
        regs.address("NOPE")


def _bus(model: RadarCtrl) -> regs.RadarRegs:
    return regs.RadarRegs(model.read, model.write)


def test_access_layer_over_the_model() -> None:
    m = RadarCtrl(max_detections=64, packet_words=512)
    r = _bus(m)
    assert r.check_id() == {"minor": 1, "major": 1}
    assert r.read("CAPS") == {"max_detections": 64, "packet_words": 512}
    assert r.read("CAPS2") == {"cfar_kinds": 0b0111, "cfar_scales": 13, "packet_words_min": 1}
    r.update("SETTINGS", cfar_kind=1, clutter_removal=1)
    r.write_cfar_scales([5, 6, 7])
    assert r.read("SETTINGS")["cfar_kind"] == 1
    assert r.read("ACTIVE_SETTINGS")["cfar_kind"] == 0       # not before the frame start
    m.step(removal_start=True, packet_start=True)            # not the detector's
    assert r.read("ACTIVE_SETTINGS")["cfar_kind"] == 0
    assert r.read("ACTIVE_SETTINGS")["clutter_removal"] == 1
    assert r.read("ACTIVE_CFAR_SCALE", index=2)["value"] == 0
    m.step(detect_start=True)
    assert r.read("ACTIVE_SETTINGS") == r.read("SETTINGS")
    assert [r.read("ACTIVE_CFAR_SCALE", index=e)["value"] for e in range(4)] == [5, 6, 7, 0]
    r.write("IRQ_ENABLE", error=1)
    m.step(error=True)
    m.step()
    assert m.irq and r.read("STATUS")["error"] == 1 and r.read("ERRORS")["count"] == 1
    r.clear_status("error")
    m.step()
    assert not m.irq and r.read("STATUS")["error"] == 0
    with pytest.raises(RuntimeError, match="ID register"):
        regs.RadarRegs(lambda a: 0, lambda a, v: None).check_id()


def test_out_of_range_write_is_refused_whole_and_counted() -> None:
    m = RadarCtrl(max_detections=8, packet_words=16)
    r = _bus(m)
    before = r.read("SETTINGS")
    r.write("SETTINGS", cfar_kind=1, max_detections=9)        # legal kind, bound exceeded
    r.write("SETTINGS", cfar_kind=3, max_detections=4)        # kind not built in (OS)
    r.write("PACKET", words=0)
    assert r.read("SETTINGS") == before and r.read("PACKET")["words"] == 16
    assert r.read("CFG_ERRORS")["count"] == 3 and r.read("STATUS")["cfg_error"] == 1
    r.write("CFAR_SCALE", index=m.n_scales, value=1)          # an entry not built in
    assert r.read("CFAR_SCALE", index=m.n_scales)["value"] == 0
    assert r.read("CFG_ERRORS")["count"] == 4
    # byte strobes: the merged word is what is checked
    m.write(regs.address("SETTINGS") + 2, 8 << 16, strb=0b1100)
    assert r.read("SETTINGS")["max_detections"] == 8
    m.write(regs.address("SETTINGS"), 3, strb=0b0001)
    assert r.read("CFG_ERRORS")["count"] == 5
    narrow = RadarCtrl(scale_w=20, packet_words_min=4)
    rn = _bus(narrow)
    rn.write("CFAR_SCALE", index=1, value=1 << 20)            # wider than SCALE_W
    rn.write("PACKET", words=3)                               # below CAPS2.packet_words_min
    assert rn.read("CFG_ERRORS")["count"] == 2 and rn.read("CFAR_SCALE", index=1)["value"] == 0


def test_counters_saturate_and_reset() -> None:
    m = RadarCtrl()
    m.counts["FRAMES"] = MASK32 - 1
    for _ in range(3):
        m.step(frame_done=True)
    assert m.read(regs.address("FRAMES")) == MASK32
    m.reset()
    assert m.read(regs.address("FRAMES")) == 0 and m.read(regs.address("STATUS")) == 0
