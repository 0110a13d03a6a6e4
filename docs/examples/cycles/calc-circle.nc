; SysCalcCircle: the example of the cycle documentation (CYCLES-ADC 4.2.5)
; Definition of return variables
#VAR
  V.CYC.SysRetRadius
  V.CYC.SysRetCenterX
  V.CYC.SysRetCenterY
  V.CYC.SysRetVariance
#ENDVAR

; cycle call
L CYCLE [NAME=SysCalcCircle.ecy \
@P50 = 0 @P60 = -1 \
@P51 = 0 @P61 = 1 \
@P52 = 1 @P62 = 0 \
@P53 = -1 @P63 = 0 ]

; print result
#FILE NAME [MSG="SysCalcCircleResult.txt"]
#MSG SAVE EXCLUSIVE["Center X = %f",V.CYC.SysRetCenterX]
#MSG SAVE EXCLUSIVE["Center Y = %f",V.CYC.SysRetCenterY]
#MSG SAVE EXCLUSIVE["Radius = %f", V.CYC.SysRetRadius]
#MSG SAVE EXCLUSIVE["Variance = %f", V.CYC.SysRetVariance]

M30
