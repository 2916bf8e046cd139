; Comments as gpx reads them: M70/M71 messages split into 20-character rows, nested parentheses, a commented line of bare axis words (no move)
M70 P5 X3 Y1 (Hello world this is a long message)
M71 (abcdefghijklmnopqrstuvwxyz0123456789 and more text here for a third row, and a fourth one past eighty)
M71
M70
X5 ; comment
G1 X5 (a (b) c) Y3
M70 ; semicolon msg
M70 Y-2 X40 (clamped)
