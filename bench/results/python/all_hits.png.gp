set terminal pngcairo noenhanced size 1100,750 font 'sans,10'
set output '/work/wt-pybench/bench/results/python/all_hits.png'
set title 'Every hit of each ray (long rays, every core): meshcast against Open3D 0.16.1 re-casting past each hit'
set xlabel 'rays'
set ylabel 'seconds (median of the rounds)'
set grid
set key top left
set logscale xy
set format x '%.0e'
set format y '%g'
set offsets graph 0.05, graph 0.05, 0, 0
plot '-' using 1:2 with linespoints lc 1 dt 1 pt 7 ps 1.3 lw 1.5 title 'terrain_2M: RaycastingScene.list_intersections', '-' using 1:2 with linespoints lc 1 dt 2 pt 5 ps 1.3 lw 1.5 title 'terrain_2M: Blob.cast all', '-' using 1:2 with linespoints lc 1 dt 3 pt 9 ps 1.3 lw 1.5 title 'terrain_2M: Open3D re-query', '-' using 1:2 with linespoints lc 2 dt 1 pt 7 ps 1.3 lw 1.5 title 'city_1M: RaycastingScene.list_intersections', '-' using 1:2 with linespoints lc 2 dt 2 pt 5 ps 1.3 lw 1.5 title 'city_1M: Blob.cast all', '-' using 1:2 with linespoints lc 2 dt 3 pt 9 ps 1.3 lw 1.5 title 'city_1M: Open3D re-query'
10000 0.03085640200151829
100000 0.252642976003699
1000000 2.769496763998177
e
10000 0.024565631996665616
100000 0.20469843300088542
1000000 2.0488082749943715
e
10000 0.058768442999280524
100000 0.5551695699978154
1000000 4.769610102004663
e
10000 0.01145176199497655
100000 0.06613364800432464
1000000 0.6206780449938378
e
10000 0.007979077003255952
100000 0.051181443996028975
1000000 0.5070439939954667
e
10000 0.020643199000915047
100000 0.1052231439971365
1000000 1.038546914998733
e
