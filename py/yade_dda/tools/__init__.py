"""Workflow tools around DDA scenes, apart from the scene API of ``yade_dda``.

- ``yade_dda.tools.compare``: ``compareColliders``, one set of blocks under
  every broad phase of the DDA core and under YADE's own colliders (also
  ``yade_dda.compareColliders``).
- ``yade_dda.tools.accuracy``: ``sweep``, one accuracy knob of a scene against
  its error and cost (also ``yade_dda.accuracySweep``).
- ``yade_dda.tools.regression``: regression scenes for ``yade-batch``: table
  parameters in, a result record out (``from yade_dda.tools import regression``).
- ``yade_dda.tools.sweep``: ``python3 -m yade_dda.tools.sweep``, every row of a
  yade-batch table as its own YADE process on Dask distributed.

``import yade_dda`` loads none of them; this package imports nothing itself,
so each tool loads only when it is imported.
"""
