"""What a run hands its user.

The command line (`cli`), VTX fields (`output`), pictures (`pictures`) and checkpoints
(`checkpoint`).
"""
