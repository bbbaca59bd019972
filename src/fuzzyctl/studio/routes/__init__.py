"""The studio's HTTP API, one router per area (FastAPI's "bigger applications" layout):
:mod:`.files` (project files, import, export), :mod:`.editing` (checking and the editors),
:mod:`.analysis` (3D display, explanations, curve recorder), :mod:`.simulation` (the
simulated process), :mod:`.online` (a running ``fuzzyctl serve``) and :mod:`.front` (the
page and its scripts).  What they share - the project directory, the controller cache, the
simulations - is one :class:`~.state.Studio` on ``app.state``, reached through the
:data:`~.state.StudioDep` dependency; :mod:`.errors` answers the exceptions."""
