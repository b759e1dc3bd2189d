set terminal pngcairo noenhanced size 1000,600 font 'sans,10'
set output '/work/main/bench/results/dask/dask.png'
set logscale x
set grid
set key bottom right
set title 'meshcast.dask on a LocalCluster against the in-process cast, closest hits (Intel(R) Xeon(R) Processor)'
set xlabel 'rays a chunk'
set ylabel 'million rays a second (wall time)'
set yrange [0:*]
set format x '10^%T'
plot '-' using 1:2 with linespoints lw 2 dt 2 title 'in process, rays from the client', '-' using 1:2 with linespoints lw 2 dt 2 title '1 worker x 2 threads, rays from the client', '-' using 1:2 with linespoints lw 2 dt 2 title '2 workers x 1 thread, rays from the client', '-' using 1:2 with linespoints lw 2 dt 1 title 'in process, rays made on the workers', '-' using 1:2 with linespoints lw 2 dt 1 title '1 worker x 2 threads, rays made on the workers', '-' using 1:2 with linespoints lw 2 dt 1 title '2 workers x 1 thread, rays made on the workers'
10000 4.101
100000 3.691
1000000 3.911
10000000 4.18
e
10000 0.68
100000 2.436
1000000 3.483
10000000 2.78
e
10000 0.808
100000 2.212
1000000 3.011
10000000 3.435
e
10000 1.988
100000 2.633
1000000 2.886
10000000 2.46
e
10000 0.521
100000 2.051
1000000 3.016
10000000 2.9
e
10000 0.616
100000 1.839
1000000 3.134
10000000 2.717
e
