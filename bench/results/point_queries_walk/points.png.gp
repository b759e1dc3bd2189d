set terminal pngcairo noenhanced size 1300,750 font 'sans,10'
set bmargin 13
set rmargin 12
set output 'bench/results/point_queries_walk/points.png'
set title 'Point queries: time over Open3D 0.16.1 RaycastingScene (below 1: faster; the target 0.5)'
set style data histograms
set style histogram cluster gap 1
set style fill solid 0.8 border -1
set boxwidth 0.9
set xtics rotate by -35 scale 0
set ylabel 'time / Open3D time'
set grid ytics
set yrange [0:*]
set key top left
set arrow from graph 0, first 1 to graph 1, first 1 nohead lw 2
set arrow from graph 0, first 0.5 to graph 1, first 0.5 nohead dt 2
plot '-' using 2:xtic(1) title 'meshcast, 1 thread(s)', '-' using 2:xtic(1) title 'meshcast, 2 thread(s)'
"bunny00 64^3 grid distance" 0.39939493385293817
"bunny00 64^3 grid signed" 0.43825311457553273
"bunny00 1,000,000 scattered distance" 0.32211868682263833
"bunny00 1,000,000 scattered signed" 0.3543840464148479
"armadillo 64^3 grid distance" 0.3611193350658465
"armadillo 64^3 grid signed" 0.48088048250112825
"armadillo 1,000,000 scattered distance" 0.2881880024737168
"armadillo 1,000,000 scattered signed" 0.36967061575611226
"refined_elephant 64^3 grid distance" 0.33247681123088496
"refined_elephant 64^3 grid signed" 0.46313725763802166
"refined_elephant 1,000,000 scattered distance" 0.29977376230351105
"refined_elephant 1,000,000 scattered signed" 0.37294610878196405
"ChineseDragon-10kv 64^3 grid distance" 0.43216217032718046
"ChineseDragon-10kv 64^3 grid signed" 0.4835559755451513
"ChineseDragon-10kv 1,000,000 scattered distance" 0.36635756788594565
"ChineseDragon-10kv 1,000,000 scattered signed" 0.4396666757441246
e
"bunny00 64^3 grid distance" 0.43490608850956686
"bunny00 64^3 grid signed" 0.458572180222093
"bunny00 1,000,000 scattered distance" 0.3182974152105759
"bunny00 1,000,000 scattered signed" 0.3861217693477159
"armadillo 64^3 grid distance" 0.4567480897897779
"armadillo 64^3 grid signed" 0.44387971198644643
"armadillo 1,000,000 scattered distance" 0.3618290623393788
"armadillo 1,000,000 scattered signed" 0.35989905143155515
"refined_elephant 64^3 grid distance" 0.37533321485693977
"refined_elephant 64^3 grid signed" 0.4194394752534288
"refined_elephant 1,000,000 scattered distance" 0.3074039554677018
"refined_elephant 1,000,000 scattered signed" 0.36844356977838627
"ChineseDragon-10kv 64^3 grid distance" 0.4856639388328057
"ChineseDragon-10kv 64^3 grid signed" 0.5169287803747792
"ChineseDragon-10kv 1,000,000 scattered distance" 0.3900963477481515
"ChineseDragon-10kv 1,000,000 scattered signed" 0.4126373481594688
e
