; A small part for docs/testing.md: a 40 x 20 mm frame with one rounded corner
N10 G90 G0 X0 Y0 Z5
N20 G1 Z0 F600
N30 X40 F3000
N40 Y15
N50 G3 X35 Y20 I-5 J0
N60 G1 X0
N70 Y0
N80 G0 Z5
N90 M30
