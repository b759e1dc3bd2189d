set terminal pngcairo noenhanced size 1300,750 font 'sans,10'
set bmargin 13
set rmargin 12
set output 'bench/results/point_queries_exact/points.png'
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
"bunny00 64^3 grid distance" 0.8913274110957082
"bunny00 64^3 grid signed" 1.0982731797286929
"bunny00 1,000,000 scattered distance" 0.7098235999479903
"bunny00 1,000,000 scattered signed" 0.8028085707198871
"armadillo 64^3 grid distance" 0.9863680231622969
"armadillo 64^3 grid signed" 1.0373175458246664
"armadillo 1,000,000 scattered distance" 0.794354776904094
"armadillo 1,000,000 scattered signed" 0.7743104372907396
"refined_elephant 64^3 grid distance" 0.8691718765671492
"refined_elephant 64^3 grid signed" 1.0527359570961705
"refined_elephant 1,000,000 scattered distance" 0.690903431170735
"refined_elephant 1,000,000 scattered signed" 0.6914394852110243
"ChineseDragon-10kv 64^3 grid distance" 1.095586227817382
"ChineseDragon-10kv 64^3 grid signed" 1.0412416661918058
"ChineseDragon-10kv 1,000,000 scattered distance" 0.934046922471025
"ChineseDragon-10kv 1,000,000 scattered signed" 0.8215859846660988
e
"bunny00 64^3 grid distance" 0.9397490786906568
"bunny00 64^3 grid signed" 1.0807373787981494
"bunny00 1,000,000 scattered distance" 0.8854102923468683
"bunny00 1,000,000 scattered signed" 0.8721940125865077
"armadillo 64^3 grid distance" 0.980861062684757
"armadillo 64^3 grid signed" 1.0325326791402731
"armadillo 1,000,000 scattered distance" 0.8050349933483718
"armadillo 1,000,000 scattered signed" 0.7755279673828394
"refined_elephant 64^3 grid distance" 1.0036766308691671
"refined_elephant 64^3 grid signed" 0.967324481374393
"refined_elephant 1,000,000 scattered distance" 0.7241876412374347
"refined_elephant 1,000,000 scattered signed" 0.7494340419000844
"ChineseDragon-10kv 64^3 grid distance" 1.084036875303251
"ChineseDragon-10kv 64^3 grid signed" 1.1021549372613202
"ChineseDragon-10kv 1,000,000 scattered distance" 0.8725942058346838
"ChineseDragon-10kv 1,000,000 scattered signed" 0.8258911913231672
e
