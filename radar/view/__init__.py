"""``radar view``: a live browser view of the radar (range-Doppler maps, point cloud with GNN
boxes, range profile, link health), like TI's mmWave Demo Visualizer.

Data flow (each stage one module)::

    source (UDP / replay of a capture / scene)                 radar.view.sources
        -> packets -> frames (cube or records), link policy      host.receiver
        -> LinkHealth counters, frames to the processor          radar.view.ingest
        -> LinkHealth counters                                    radar.view.health
        -> host processing of the newest frame                    radar.view.processor
        -> ViewFrame (cube and/or point cloud, objects)           radar.view.feed
        -> Feed: newest frame only, never a queue                 radar.view.feed
        -> per browser: JSON message (downsampled, quantised)     radar.view.render
        -> aiohttp WebSocket, one frame in flight per browser     radar.view.server
        -> plotly.js page shipped in the package                  radar/view/static/

The command itself (options, wiring of the stages) is :mod:`radar.commands.view`.
"""
