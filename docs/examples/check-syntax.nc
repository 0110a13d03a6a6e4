;Test syntax check of decoder)
%check_syntax

;□ overflow error
N40 G01 X10 F1111111111111111

(□ syntax error
N50 #COMMAND UNKNOWN [...]

(□ syntax error
N60 V.E.not_present = 1

(□ syntax error
N70 #CALL AX [X2, 11, 0]

(-> semantic error
N80 G00 G01 X100 F1000

N130 M30
