set terminal pngcairo size 1000,650 font ',11'
set output 'bottleneck.png'
set datafile separator ','
set title 'Flow through a bottleneck against its width'
set xlabel 'width b [m]'
set ylabel 'flow J [1/s]'
set xrange [0.6:2.7]
set yrange [0:*]
set grid
set key top left
plot 1.9 * x with lines lw 2 dt 2 lc rgb 'black' title 'J = 1.9 b (specific flow as usually quoted for the Juelich experiments)', \
     'bottleneck.csv' using (strcol(1) eq 'orca' ? $2 : 1/0):3:8:9 skip 1 with yerrorlines pt 5 ps 1.5 title 'orca', \
     'bottleneck.csv' using (strcol(1) eq 'cfsm' ? $2 : 1/0):3:8:9 skip 1 with yerrorlines pt 6 ps 1.5 title 'cfsm'
