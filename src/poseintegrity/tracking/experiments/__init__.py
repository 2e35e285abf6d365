"""Stage 06's experiments (III), one module each, and the peers they are compared with (filterpy, pykalman).
"""
