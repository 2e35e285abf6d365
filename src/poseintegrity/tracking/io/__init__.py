"""Recorded input: recording folders (ours), HoloLens 2 AHAT recordings (StreamRecorder, hl2ss), tool files.

    recording.py         the recording folder (frames, lookup table, gyro, manifest), read and written
    hl2_recordings.py    HoloLens 2 AHAT recordings of StreamRecorder and hl2ss -> a recording folder
    tool_files.py        tool files (JSON, CSV) read and written
    timestamps.py        the clock's range, shared by the recording folder and the trackers
"""
