"""The view's link: DMA packets (UDP datagrams or a replayed capture) -> a
``host.receiver.Receiver`` (geometry and kind learnt, sender restarts, lost frames) -> the
:class:`radar.view.processor.Processor`, keeping :class:`radar.view.health.LinkHealth`
current. Never raises on bad data."""

from __future__ import annotations

from collections.abc import Sequence

from host.receiver import CUBE, DetectConfigOf, LinkFrame, Receiver
from host.records import DetectionFrame
from host.stream import StreamStats
from model.config import RadarConfig
from model.radar_pipeline import PipelineParams
from radar.view.health import LinkHealth
from radar.view.processor import Processor


class ViewLink:
    """A receiver's events (``host.receiver.LinkEvents``) -> link health; its frames (all,
    or only complete ones unless ``use_damaged``) -> the processor."""

    def __init__(self, health: LinkHealth, processor: Processor, use_damaged: bool = True
                 ) -> None:
        self.health = health
        self.processor = processor
        self.use_damaged = use_damaged

    def on_datagram(self, nbytes: int) -> None:
        self.health.on_datagram(nbytes)

    def on_kind(self, kind: str, max_detections: int | None = None) -> None:
        self.health.on_kind(kind, max_detections)

    def on_problem(self, message: str) -> None:
        with self.health.lock:
            self.health.problems.append(message)

    def on_decoder(self, stats: StreamStats, problems: list[str]) -> None:
        self.health.on_decoder(stats, problems)

    def retire_decoder(self, stats: StreamStats) -> None:
        self.health.retire_decoder(stats)

    def on_frame(self, frame: LinkFrame, cfg: RadarConfig, packet_words: int,
                 n_packets: int, id_gap: int) -> None:
        self.health.on_frame(frame, packet_words, n_packets, id_gap)
        if isinstance(frame, DetectionFrame):
            tr = frame.trailer
            self.health.on_record_frame(len(frame.records), frame.detections, frame.truncated,
                                        bool(tr and tr.truncated_sticky))
        if frame.complete or self.use_damaged:
            self.processor.submit(frame.frame_id, frame, cfg)


def packet_ingest(cfg: RadarConfig, packet_words: int | None, health: LinkHealth,
                  processor: Processor, use_damaged: bool = True,
                  configs: Sequence[RadarConfig] | None = None, kind: str | None = CUBE,
                  detect_config: DetectConfigOf | None = None,
                  chain: PipelineParams | None = None) -> Receiver:
    """The receiver of the view's link, its decoder built (ValueError on a bad geometry).
    ``cfg``: the preset assumed first; ``configs``: the presets the stream may be of
    (default ``cfg`` only; with more, the preset is learnt from the headers too); the rest
    as ``host.receiver.Receiver``."""
    rx = Receiver([cfg, *(configs or [])], packet_words, kind, detect_config, chain,
                  ViewLink(health, processor, use_damaged))
    rx.open()
    return rx
