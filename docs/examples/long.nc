; long.nc: 4 s of X (100 mm at F1500, 100 % override), long enough to hold and resume
N10 G1 X0 Y0 F1500
N20 G1 X100
N30 M30
