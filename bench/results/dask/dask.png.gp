set terminal pngcairo noenhanced size 1000,600 font 'sans,10'
set output '/work/main/bench/results/dask/dask.png'
set logscale x
set grid
set key bottom right
set title 'meshcast.dask against the in-process cast, closest hits on bunny00 (Intel(R) Xeon(R) Processor)'
set xlabel 'rays a chunk'
set ylabel 'million rays a second (wall, answers in the client)'
set yrange [0:*]
set format x '10^{%L}'
plot '-' using 1:2 with linespoints lw 2 title 'in process', '-' using 1:2 with linespoints lw 2 title '1 worker x 2 threads', '-' using 1:2 with linespoints lw 2 title '2 workers x 1 thread'
10000 4.159
100000 3.894
1000000 3.902
10000000 4.035
e
10000 0.622
100000 2.556
1000000 2.819
10000000 2.772
e
10000 0.716
100000 2.325
1000000 3.076
10000000 2.74
e
