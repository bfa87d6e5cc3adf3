//! Parsing throughput (bytes of input per second) of every loader, on generated in-memory
//! input of a few MB (no real data needed).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::fmt::Write;
use std::hint::black_box;
use trajpred_data::{LoadOptions, LoadReport, adsb, csvfile, geolife, tdrive};

const N: usize = 50_000;

fn plt() -> String {
    let mut s = String::from(
        "Geolife trajectory\r\nWGS 84\r\nAltitude is in Feet\r\nReserved 3\r\n0,2,255,My Track,0,0,2,8421376\r\n0\r\n",
    );
    for i in 0..N {
        let (h, m, sec) = (i / 3600 % 24, i / 60 % 60, i % 60);
        let day = 1 + i / 86_400;
        writeln!(
            s,
            "{:.6},{:.6},0,{},{:.10},2008-10-{day:02},{h:02}:{m:02}:{sec:02}\r",
            39.9 + 1e-5 * i as f64,
            116.3 + 1e-5 * (i % 977) as f64,
            400 + i % 100,
            39744.0 + i as f64 / 86_400.0
        )
        .unwrap();
    }
    s
}

fn tdrive_log() -> String {
    let mut s = String::new();
    for i in 0..N {
        let (h, m, sec) = (i / 3600 % 24, i / 60 % 60, i % 60);
        let day = 2 + i / 86_400;
        writeln!(
            s,
            "7,2008-02-{day:02} {h:02}:{m:02}:{sec:02},{:.5},{:.5}",
            116.3 + 1e-5 * (i % 977) as f64,
            39.9 + 1e-5 * (i % 1013) as f64
        )
        .unwrap();
    }
    s
}

fn adsb_records() -> String {
    let mut s = String::from("[");
    for i in 0..N {
        if i > 0 {
            s.push(',');
        }
        write!(
            s,
            r#"{{"timestamp":{},"icao24":"{:06x}","latitude":{:.10},"longitude":{:.10},"groundspeed":155.0,"track":3.0,"vertical_rate":2240.0,"callsign":"TRA{:03}","altitude":{}}}"#,
            1_527_693_698_000u64 + (i as u64 / 10) * 1000,
            0x484506 + i % 10,
            52.3 + 1e-5 * i as f64,
            4.7 + 1e-5 * i as f64,
            i % 10,
            1000 + i % 5000
        )
        .unwrap();
    }
    s.push(']');
    s
}

fn adsb_columns() -> String {
    let col = |name: &str, f: &dyn Fn(usize) -> String| {
        let body: Vec<String> = (0..N).map(|i| format!("\"{i}\":{}", f(i))).collect();
        format!("\"{name}\":{{{}}}", body.join(","))
    };
    let cols = [
        col("timestamp", &|i| {
            (1_576_068_400_000u64 + i as u64 * 1000).to_string()
        }),
        col("icao24", &|_| "\"39c902\"".into()),
        col("callsign", &|_| "\"FHMAC\"".into()),
        col("latitude", &|i| format!("{:.10}", 43.6 + 1e-5 * i as f64)),
        col("longitude", &|i| format!("{:.10}", 7.2 + 1e-5 * i as f64)),
        col("altitude", &|i| format!("{}", 1000 + i % 3000)),
    ];
    format!("{{{}}}", cols.join(","))
}

fn csv_latlon() -> String {
    let mut s = String::from("t,lat,lon,alt\n");
    for i in 0..N {
        writeln!(
            s,
            "{i},{:.7},{:.7},{:.1}",
            39.9 + 1e-5 * i as f64,
            116.3 + 1e-5 * (i % 977) as f64,
            50.0 + (i % 100) as f64 * 0.5
        )
        .unwrap();
    }
    s
}

fn bench(c: &mut Criterion) {
    let opts = LoadOptions::default();
    let adsb_opts = LoadOptions::adsb();
    let inputs: [(&str, String); 5] = [
        ("geolife_plt", plt()),
        ("tdrive", tdrive_log()),
        ("adsb_records_json", adsb_records()),
        ("adsb_columns_json", adsb_columns()),
        ("csv_lat_lon_alt", csv_latlon()),
    ];
    let mut g = c.benchmark_group("parse");
    g.sample_size(10);
    for (name, text) in &inputs {
        let bytes = text.as_bytes();
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(*name, |b| {
            b.iter(|| {
                let mut r = LoadReport::new();
                let tracks = match *name {
                    "geolife_plt" => geolife::parse_plt(bytes, "bench", "bench", &opts, &mut r),
                    "tdrive" => tdrive::parse(bytes, "bench", &opts, &mut r),
                    "adsb_records_json" => adsb::parse_json(bytes, "bench", &adsb_opts, &mut r),
                    "adsb_columns_json" => adsb::parse_json(bytes, "bench", &adsb_opts, &mut r),
                    _ => csvfile::parse(bytes, "bench", &opts, &mut r),
                }
                .expect("generated input parses");
                assert_eq!(r.skipped_total(), 0, "{name}: {r}");
                black_box(tracks)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
