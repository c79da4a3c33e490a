"""What a run hands its user.

The command line (`cli`, `parameters`), VTX fields (`output`), a punch run's JSON
(`indentation_record`) and checkpoints (`checkpoint`, `restart`); the pictures are
`fenics_nl.plots`.
"""
