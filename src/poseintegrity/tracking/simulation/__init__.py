"""The simulation study's world (II-F): AHAT-like IR and depth frames, hand-like motion, a simulated recording run
through the pipeline, and the paper's error measures.
"""
