; Seed 001's demo part for the five-MCU printer (bench/boards/printer3d-seed001.yaml,
; firmware/printer3d_interp): two layers of a 6 x 6 mm square outline with one
; corner rounded (R 2 mm), 0.2 mm layers, the extruder on while depositing
; (M3/M5, SP steps per tick). Coordinates in mm from the homed corner.
G28                     ; home X, Y, Z on their switches
G90
G1 Z0.2 F300            ; first layer (Z moves alone)
G1 X2 Y2 F600           ; travel to the start, extruder off
M3                      ; extruder on: G1/G2/G3 deposit
G1 X8 Y2 F500
G1 X8 Y6
G3 X6 Y8 I-2 J0 F300    ; the rounded corner, counter-clockwise about (6, 6)
G1 X2 Y8 F500
G1 X2 Y2
M5                      ; extruder off, retract
G1 Z0.4 F300            ; layer change
M3
G1 X8 Y2 F500
G1 X8 Y6
G3 X6 Y8 I-2 J0 F300
G1 X2 Y8 F500
G1 X2 Y2
M5
G0 Z2                   ; lift and park
G0 X0 Y0
M400
M114
