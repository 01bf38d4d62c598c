"""Parameter studies and paper reproductions. Each study runs alone
(``python -m studies.NAME [--quick] [--out DIR]``), writes its table (CSV) and figure (PNG) under
``reports/``, and returns its table to the report:

* ``cantilever_convergence``: the cantilever of Section 3.1 at growing node density (cf. Fig. 9),
  CTM-RPIM against scikit-fem Q1, P1 and P2 on the same node grids;
* ``plate_hole_convergence``: the Kirsch plate with a hole, plane stress and plane strain.
"""
