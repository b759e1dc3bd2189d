set terminal pngcairo noenhanced size 1300,750 font 'sans,10'
set bmargin 13
set rmargin 12
set output 'bench/results/point_queries_single/points.png'
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
"bunny00 64^3 grid distance" 0.3756994609972836
"bunny00 64^3 grid signed" 0.37829430866518543
"bunny00 1,000,000 scattered distance" 0.29020144090454514
"bunny00 1,000,000 scattered signed" 0.31622955796364977
"armadillo 64^3 grid distance" 0.30858343407786476
"armadillo 64^3 grid signed" 0.3872167029828514
"armadillo 1,000,000 scattered distance" 0.27361807596979654
"armadillo 1,000,000 scattered signed" 0.3180625584631881
"refined_elephant 64^3 grid distance" 0.3401903279311336
"refined_elephant 64^3 grid signed" 0.33575891594456303
"refined_elephant 1,000,000 scattered distance" 0.25777049516104256
"refined_elephant 1,000,000 scattered signed" 0.26530429450388937
"ChineseDragon-10kv 64^3 grid distance" 0.36252031449027106
"ChineseDragon-10kv 64^3 grid signed" 0.4149280726844452
"ChineseDragon-10kv 1,000,000 scattered distance" 0.32511244377811094
"ChineseDragon-10kv 1,000,000 scattered signed" 0.34983087057147944
"city_1M 64^3 grid distance" 0.6732679654238163
"city_1M 64^3 grid signed" 0.7639459776864357
"city_1M 1,000,000 scattered distance" 0.606076210092688
"city_1M 1,000,000 scattered signed" 0.6258492975734354
e
"bunny00 64^3 grid distance" 0.37431108926878925
"bunny00 64^3 grid signed" 0.39514755465952933
"bunny00 1,000,000 scattered distance" 0.30365124670149174
"bunny00 1,000,000 scattered signed" 0.33543320197591164
"armadillo 64^3 grid distance" 0.3843508788804194
"armadillo 64^3 grid signed" 0.4164164596608705
"armadillo 1,000,000 scattered distance" 0.31407917063759555
"armadillo 1,000,000 scattered signed" 0.33362196201908884
"refined_elephant 64^3 grid distance" 0.33194981605508916
"refined_elephant 64^3 grid signed" 0.3580734509643004
"refined_elephant 1,000,000 scattered distance" 0.2725302184155465
"refined_elephant 1,000,000 scattered signed" 0.2910234127389837
"ChineseDragon-10kv 64^3 grid distance" 0.3708311733195092
"ChineseDragon-10kv 64^3 grid signed" 0.4594572502860879
"ChineseDragon-10kv 1,000,000 scattered distance" 0.3534111638088289
"ChineseDragon-10kv 1,000,000 scattered signed" 0.3537645879804739
"city_1M 64^3 grid distance" 0.7971217524197656
"city_1M 64^3 grid signed" 0.8394543546694648
"city_1M 1,000,000 scattered distance" 0.6258418816702932
"city_1M 1,000,000 scattered signed" 0.7327480604328297
e
