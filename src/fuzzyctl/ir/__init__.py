"""The lowered form every backend is printed from: IR nodes (:mod:`~fuzzyctl.ir.nodes`), the
builders that write each semantic once (:mod:`~fuzzyctl.ir.builders`), the programs
(:mod:`~fuzzyctl.ir.programs`: the PLC block, the evaluator, the rule table) and the renderers
(:mod:`~fuzzyctl.ir.render`: Python, numpy, C, ST; PLCopen XML wraps the ST in
:mod:`fuzzyctl.codegen.plcopen`)."""
