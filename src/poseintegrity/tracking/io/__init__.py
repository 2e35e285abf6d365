"""Recorded input: recording folders (ours), HoloLens 2 AHAT recordings (StreamRecorder, hl2ss), tool files.
"""
