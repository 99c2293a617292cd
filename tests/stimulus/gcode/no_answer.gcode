; no_answer.gcode: stepdir_test never answers T
E1
X5

T   ; the firmware stays silent here
X5
