; A square on the UNO + CNC shield with stepdir_test's line commands:
; 250 steps/mm, so 1000 steps = 4 mm per side.
E1        ; enable the drivers (PB0 low)
L45       ; 50 us per step: 20 000 steps/s = 80 mm/s
X1000
Y1000
X-1000
Y-1000
Z250      ; lift 1 mm
?         ; report the position
E0
