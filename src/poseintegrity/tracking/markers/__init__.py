"""Markers in a frame (Black and Salcudean II-B, II-D, Alg. 1-4): detection in the IR + depth frame, correspondence
to the tool geometry, Kabsch, and the tool geometry checks.
"""
