; short_job.gcode: a small stepdir_test job (commands: firmware/boards/stepdir_test/README.md)
(every comment form a sender strips: full-line, trailing, parentheses)

E1 ; enable the drivers
W5
L45 (45 us low: 20 kHz with W5)

X10
X-10
Y20
Z-5 (down)
?
E0
