"""Surface-surface intersection with a no-missed-loop guarantee: the oriented
distance function, characteristic points and characteristic curves
(Wang, Gursoz, Chen, Prinz, Patrikalakis 1990; paper 002)."""
