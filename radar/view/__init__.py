"""``radar view``: a live browser view of the radar (range-Doppler maps, point cloud with GNN
boxes, range profile, link health), like TI's mmWave Demo Visualizer.

Data flow (each stage one module)::

    source (UDP / replay / scene / later: detection records)   radar.view.sources
        -> LinkHealth counters                                    radar.view.health
        -> ViewFrame (cube and/or point cloud, objects)           radar.view.feed
        -> Feed: newest frame only, never a queue                 radar.view.feed
        -> per browser: JSON message (downsampled, quantised)     radar.view.render
        -> aiohttp WebSocket, one frame in flight per browser     radar.view.server
        -> plotly.js page shipped in the package                  radar/view/static/

The command itself (options, wiring of the stages) is :mod:`radar.commands.view`.
"""
