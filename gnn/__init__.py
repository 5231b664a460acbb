"""RadarGNN-style object detector for the radar's point clouds (docs/gnn.md).

Modules, one job each: ``classes`` (class list), ``boxes`` (rotated boxes, IoU, NMS),
``synth_scenes`` (random labelled scenes), ``render`` (scene -> point cloud through the
radar), ``labelling`` (points -> objects), ``frame`` / ``dataset`` (labelled frames, cache),
``radarscenes`` (RadarScenes loader), ``graph`` (graph + features), ``model`` (network),
``losses``, ``train``, ``checkpoint``, ``detection`` (decoder), ``infer``
(``detect_objects``), ``metrics``, ``baseline`` (DBSCAN + rules), ``evaluate``, ``cli``.
The latency benchmark is ``benchmarks/bench_infer.py`` (outside the package).
"""
