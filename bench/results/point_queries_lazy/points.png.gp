set terminal pngcairo noenhanced size 1300,750 font 'sans,10'
set bmargin 13
set rmargin 12
set output 'bench/results/point_queries_lazy/points.png'
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
"bunny00 64^3 grid distance" 0.40118349338178044
"bunny00 64^3 grid signed" 0.4577668716270848
"bunny00 1,000,000 scattered distance" 0.3463639759673754
"bunny00 1,000,000 scattered signed" 0.36938190500087437
"armadillo 64^3 grid distance" 0.3596590539397489
"armadillo 64^3 grid signed" 0.40674980714836717
"armadillo 1,000,000 scattered distance" 0.31587642112267256
"armadillo 1,000,000 scattered signed" 0.3339099624843685
"refined_elephant 64^3 grid distance" 0.35469458199590304
"refined_elephant 64^3 grid signed" 0.4036195883605394
"refined_elephant 1,000,000 scattered distance" 0.3104509357262419
"refined_elephant 1,000,000 scattered signed" 0.31545375896300426
"ChineseDragon-10kv 64^3 grid distance" 0.4100606684725425
"ChineseDragon-10kv 64^3 grid signed" 0.4494932643783626
"ChineseDragon-10kv 1,000,000 scattered distance" 0.3634662875102896
"ChineseDragon-10kv 1,000,000 scattered signed" 0.3649798987613731
"city_1M 64^3 grid distance" 0.827237311979223
"city_1M 64^3 grid signed" 0.8378723404255319
"city_1M 1,000,000 scattered distance" 0.5704363581458554
"city_1M 1,000,000 scattered signed" 0.6708775959421953
e
"bunny00 64^3 grid distance" 0.43442573601717877
"bunny00 64^3 grid signed" 0.46561965360143015
"bunny00 1,000,000 scattered distance" 0.33677132773518315
"bunny00 1,000,000 scattered signed" 0.3701038103277208
"armadillo 64^3 grid distance" 0.40044917488526516
"armadillo 64^3 grid signed" 0.44726737152175056
"armadillo 1,000,000 scattered distance" 0.33445749505756484
"armadillo 1,000,000 scattered signed" 0.3704533420227282
"refined_elephant 64^3 grid distance" 0.40044062781422873
"refined_elephant 64^3 grid signed" 0.449442522106882
"refined_elephant 1,000,000 scattered distance" 0.3133847293000566
"refined_elephant 1,000,000 scattered signed" 0.3390539853229674
"ChineseDragon-10kv 64^3 grid distance" 0.4360572281225314
"ChineseDragon-10kv 64^3 grid signed" 0.480963796676283
"ChineseDragon-10kv 1,000,000 scattered distance" 0.39525792780944036
"ChineseDragon-10kv 1,000,000 scattered signed" 0.4347544559179361
"city_1M 64^3 grid distance" 0.8477759852500577
"city_1M 64^3 grid signed" 0.8573163997791275
"city_1M 1,000,000 scattered distance" 0.6981592596359198
"city_1M 1,000,000 scattered signed" 0.7556164383561643
e
