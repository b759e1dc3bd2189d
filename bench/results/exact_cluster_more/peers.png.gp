set terminal pngcairo noenhanced size 1100,750 font 'sans,10'
set output 'bench/results/exact_cluster_more/peers.png'
set title 'time against bytes, geometric mean over the rows'
set xlabel 'bytes a triangle, all included'
set ylabel 'time a ray / Embree default time a ray'
set grid
set key top right
set offsets graph 0.02, graph 0.15, graph 0.05, graph 0.05
plot '-' using 1:2 with points pt 7 ps 1.2 lc 1 title 'meshcast', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt 1 notitle, '-' using 1:2 with points pt 7 ps 1.2 lc 2 title 'Embree', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt 2 notitle
13.633 1.36322 "OctTreeCompressed/ClusterBitPackSOA8"
19.4481 1.30808 "OctTreeCompressed/ClusterFloat3SOA8"
e
13.633 1.36322 "OctTreeCompressed/ClusterBitPackSOA8"
19.4481 1.30808 "OctTreeCompressed/ClusterFloat3SOA8"
e
86.0176 1 "Embree 3.13.5 default"
87.4531 1.02283 "Embree 3.13.5 high quality"
86.0176 1.21683 "Embree 3.13.5 robust"
53.9658 1.35722 "Embree 3.13.5 compact"
e
86.0176 1 "Embree 3.13.5 default"
87.4531 1.02283 "Embree 3.13.5 high quality"
86.0176 1.21683 "Embree 3.13.5 robust"
53.9658 1.35722 "Embree 3.13.5 compact"
e
