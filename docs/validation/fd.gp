set terminal pngcairo size 1000,650 font ',11'
set output 'fd.png'
set datafile separator ','
set title 'Speed against density: a ring corridor 4 m wide, all walking one way (RiMEA 4)'
set xlabel 'density [1/m^2]'
set ylabel 'speed [m/s]'
set xrange [0:5.5]
set yrange [0:1.6]
set grid
set key top right
weidmann(r) = r <= 0 ? 1.34 : 1.34 * (1 - exp(-1.913 * (1 / r - 1 / 5.4)))
plot weidmann(x) with lines lw 2 dt 2 lc rgb 'black' title 'Weidmann 1993', \
     'fd.csv' using (strcol(1) eq 'orca' ? $3 : 1/0):4 skip 1 with points pt 5 ps 1.5 title 'orca', \
     'fd.csv' using (strcol(1) eq 'cfsm' ? $3 : 1/0):4 skip 1 with points pt 6 ps 1.5 title 'cfsm'
