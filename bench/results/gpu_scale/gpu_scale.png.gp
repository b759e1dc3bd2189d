set terminal pngcairo noenhanced size 1100,750 font 'sans,10'
set output 'bench/results/gpu_scale/gpu_scale.png'
set title 'rays a second against batch size, llvmpipe (LLVM 15.0.6, 256 bits)'
set xlabel 'rays a batch'
set ylabel 'rays a second'
set grid
set key top right
set offsets graph 0.02, graph 0.15, graph 0.05, graph 0.05
set logscale y
set ytics 2
set format y '%.1e'
set logscale x
set xtics 2
set format x '%g'
set autoscale fix
plot '-' using 1:2 with linespoints pt 7 ps 1.2 lc 1 title 'GPU device', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt 1 notitle, '-' using 1:2 with linespoints pt 7 ps 1.2 lc 2 title 'GPU wall, one batch', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt 2 notitle, '-' using 1:2 with linespoints pt 7 ps 1.2 lc 3 title 'GPU stream', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt 3 notitle, '-' using 1:2 with linespoints pt 7 ps 1.2 lc 4 title 'CPU, every core', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt 4 notitle
1024 194932 ""
16384 301718 ""
262144 301932 ""
1.04858e+06 297891 ""
4.1943e+06 301609 ""
e
1024 194932 ""
16384 301718 ""
262144 301932 ""
1.04858e+06 297891 ""
4.1943e+06 301609 ""
e
1024 189660 ""
16384 300765 ""
262144 301864 ""
1.04858e+06 297867 ""
4.1943e+06 301603 ""
e
1024 189660 ""
16384 300765 ""
262144 301864 ""
1.04858e+06 297867 ""
4.1943e+06 301603 ""
e
1024 269967 ""
16384 302210 ""
262144 296589 ""
1.04858e+06 297586 ""
4.1943e+06 298511 ""
e
1024 269967 ""
16384 302210 ""
262144 296589 ""
1.04858e+06 297586 ""
4.1943e+06 298511 ""
e
1024 2.41864e+06 ""
16384 7.37314e+06 ""
262144 7.63852e+06 ""
1.04858e+06 8.20688e+06 ""
4.1943e+06 8.49964e+06 ""
e
1024 2.41864e+06 ""
16384 7.37314e+06 ""
262144 7.63852e+06 ""
1.04858e+06 8.20688e+06 ""
4.1943e+06 8.49964e+06 ""
e
