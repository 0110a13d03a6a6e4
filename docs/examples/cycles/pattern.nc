; A user cycle (drill.ecy, in the program store) at the three positions of a call pattern;
; the second position turns the cycle by 60 degrees about Z (CYCLES-ADC 3.3)
#PATTERN BEGIN [ID=1]
#AT [100, 0, 0]
#AT [100, 100, 5, 0, 0, 60]
#AT [0 , 100, 10]
#PATTERN END

G00 Z60
G00 X50 Y50          ( Positioning to the starting point )
L CYCLE [NAME=drill.ecy \
  @P1 = 2            \
  PATTERN_ID = 1     \
  PATTERN_RETRACT = 100 \
]
M30
