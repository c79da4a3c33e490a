"""What a run hands its user: command line, VTX fields, pictures."""
