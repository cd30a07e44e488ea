"""Figures the source paper states ("Wind on Trees", CITATION.cff),
quoted once here so tables can print them beside what physgs measures."""

#: Section 4, null control: the median nearest-bone gap of each tree (percent).
NEAREST_BONE_GAP_PCT = {"sparse": 5.40, "medium": 0.40, "dense": 0.15}
#: Section 3, wind: natural frequencies span ~4.3x (0.35-1.5 Hz).
FREQUENCY_SPAN = 4.3
#: Section 3, geometry: animated bones per tree.
BONES = {"sparse": 22, "medium": 224, "dense": 562}
