//! One ray a call through the safe crate, in a loop: the median of 11
//! rounds of 200,000 calls for each ray of RAYS (bench/c_api_bench.cpp
//! writes a miss and a hit), ns a call.
//!   cargo run --release --offline --example one_ray -- BLOB RAYS
use meshcast::{Blob, Hit, Query, Ray};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    assert!(args.len() == 3, "usage: one_ray BLOB RAYS");
    let blob = Blob::load(&args[1]).unwrap();
    let bytes = std::fs::read(&args[2]).unwrap();
    let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let query = Query::default();
    for k in 0..word(4) as usize {
        let f = |i: usize| f32::from_bits(word(8 + 28 * k + 4 * i));
        let ray = [Ray { org: [f(0), f(1), f(2)], dir: [f(3), f(4), f(5)], tmax: f(6), tmin: 0.0 }];
        let mut hit = [Hit::default()];
        let calls = 200_000;
        let mut times: Vec<f64> = (0..11)
            .map(|_| {
                let start = Instant::now();
                for _ in 0..calls {
                    blob.cast(&ray, &mut hit, &query).unwrap();
                }
                start.elapsed().as_secs_f64() * 1e9 / calls as f64
            })
            .collect();
        times.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let what = if hit[0].triangle == meshcast::NO_HIT { "a miss" } else { "a hit" };
        println!("| Rust | ray {} ({}) | {:.1} ns a call |", k, what, times[times.len() / 2]);
    }
}
