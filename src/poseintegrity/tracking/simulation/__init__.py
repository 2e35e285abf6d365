"""The simulation study's world (II-F): AHAT-like IR and depth frames, hand-like motion, a simulated recording run
through the pipeline, and the paper's error measures.

    frames.py            ours: AHAT-like IR + depth frames with markers, phantoms and noise
    motion.py            II-F: motion (a) paper-like and (b) stress, and the sensor timeline
    pace.py              motion (c): the paper's pace, from its lag and errors
    simulate.py          a simulated recording through the pipeline, without and with the filter
    errors.py            II-F: the paper's per-axis / Euler RMS beside norm / geodesic errors
"""
