//! Geodesy against independent references:
//! - the WGS84 defining constants (a = 6 378 137 m on the equator at 0°E, b = 6 356 752.314 245 m
//!   at the poles; NIMA TR8350.2, 3rd ed., tables 3.1 and 3.3);
//! - pymap3d 3.2.0 (`fixtures/data/geodesy_pymap3d.json`, made by `make_geodesy.py` beside it).
//!
//! Tolerance: 1 mm for ECEF/ENU (the bar; both implementations agree to ~1e-8 m in
//! practice), 1e-9 degrees for round trips.

use serde::Deserialize;
use trajpred_data::geodesy::{
    Ecef, Enu, Geodetic, LocalFrame, WGS84_A, ecef_to_geodetic, geodetic_to_ecef,
};

#[derive(Deserialize)]
struct EcefRow {
    lat: f64,
    lon: f64,
    alt: f64,
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Deserialize)]
struct EnuRow {
    #[serde(rename = "ref")]
    reference: [f64; 3],
    lat: f64,
    lon: f64,
    alt: f64,
    e: f64,
    n: f64,
    u: f64,
}

#[derive(Deserialize)]
struct Fixture {
    ecef: Vec<EcefRow>,
    enu: Vec<EnuRow>,
}

fn fixture() -> Fixture {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/data/geodesy_pymap3d.json"
    );
    let text = std::fs::read_to_string(path).expect("fixture present");
    serde_json::from_str(&text).expect("fixture parses")
}

fn g(lat: f64, lon: f64, alt: f64) -> Geodetic {
    Geodetic::new(lat, lon, alt).expect("valid position")
}

#[test]
fn defining_constants_of_wgs84() {
    let e = geodetic_to_ecef(&g(0.0, 0.0, 0.0));
    assert_eq!((e.x, e.y, e.z), (WGS84_A, 0.0, 0.0));
    let e = geodetic_to_ecef(&g(0.0, 90.0, 0.0));
    assert!(e.x.abs() < 1e-9 && (e.y - 6_378_137.0).abs() < 1e-9);
    let pole = geodetic_to_ecef(&g(90.0, 0.0, 0.0));
    assert!((pole.z - 6_356_752.314_245).abs() < 1e-3, "{}", pole.z);
    let back = ecef_to_geodetic(&Ecef {
        x: 0.0,
        y: 0.0,
        z: -6_356_752.314_245,
    });
    assert!((back.lat_deg + 90.0).abs() < 1e-12 && back.alt_m.abs() < 1e-3);
}

#[test]
fn ecef_matches_pymap3d_to_a_millimetre() {
    let f = fixture();
    assert!(f.ecef.len() >= 10);
    for r in &f.ecef {
        let e = geodetic_to_ecef(&g(r.lat, r.lon, r.alt));
        for (got, want) in [(e.x, r.x), (e.y, r.y), (e.z, r.z)] {
            assert!(
                (got - want).abs() < 1e-3,
                "{} {}: {got} vs {want}",
                r.lat,
                r.lon
            );
        }
        let back = ecef_to_geodetic(&Ecef {
            x: r.x,
            y: r.y,
            z: r.z,
        });
        assert!(
            (back.lat_deg - r.lat).abs() < 1e-9,
            "{} vs {}",
            back.lat_deg,
            r.lat
        );
        if r.lat.abs() < 90.0 {
            let dlon = (back.lon_deg - r.lon + 540.0).rem_euclid(360.0) - 180.0;
            assert!(dlon.abs() < 1e-9, "{} vs {}", back.lon_deg, r.lon);
        }
        assert!(
            (back.alt_m - r.alt).abs() < 1e-3,
            "{} vs {}",
            back.alt_m,
            r.alt
        );
    }
}

#[test]
fn enu_matches_pymap3d_to_a_millimetre() {
    let f = fixture();
    assert!(f.enu.len() >= 10);
    for r in &f.enu {
        let frame = LocalFrame::new(g(r.reference[0], r.reference[1], r.reference[2])).unwrap();
        let p = frame.to_enu(&g(r.lat, r.lon, r.alt));
        for (got, want) in [(p.east, r.e), (p.north, r.n), (p.up, r.u)] {
            assert!((got - want).abs() < 1e-3, "{got} vs {want}");
        }
        let back = frame.to_geodetic(&Enu {
            east: r.e,
            north: r.n,
            up: r.u,
        });
        assert!((back.lat_deg - r.lat).abs() < 1e-9);
        assert!((back.lon_deg - r.lon).abs() < 1e-9);
        assert!((back.alt_m - r.alt).abs() < 1e-3);
    }
}

#[test]
fn invalid_positions_are_typed_errors() {
    for (lat, lon, alt) in [
        (90.5, 0.0, 0.0),
        (f64::NAN, 0.0, 0.0),
        (0.0, f64::INFINITY, 0.0),
        (0.0, 0.0, f64::NAN),
    ] {
        assert!(matches!(
            Geodetic::new(lat, lon, alt),
            Err(trajpred_data::Error::Core(
                trajpred_core::Error::InvalidParameter { .. }
            ))
        ));
    }
    let bad = Geodetic {
        lat_deg: 91.0,
        lon_deg: 0.0,
        alt_m: 0.0,
    };
    assert!(matches!(
        LocalFrame::new(bad),
        Err(trajpred_data::Error::Core(
            trajpred_core::Error::InvalidParameter {
                name: "lat_deg",
                ..
            }
        ))
    ));
}

mod props {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn enu_round_trip_within_1e9_degrees(
            lat0 in -89.0f64..89.0, lon0 in -180.0f64..180.0, h0 in -500.0f64..5000.0,
            dlat in -0.5f64..0.5, dlon in -0.5f64..0.5, h in -500.0f64..15000.0,
        ) {
            let frame = LocalFrame::new(g(lat0, lon0, h0)).unwrap();
            let lat = (lat0 + dlat).clamp(-90.0, 90.0);
            let p = g(lat, lon0 + dlon, h);
            let back = frame.to_geodetic(&frame.to_enu(&p));
            prop_assert!((back.lat_deg - p.lat_deg).abs() < 1e-9);
            let dl = (back.lon_deg - p.lon_deg + 540.0).rem_euclid(360.0) - 180.0;
            prop_assert!(dl.abs() < 1e-9);
            prop_assert!((back.alt_m - p.alt_m).abs() < 1e-6);
        }
    }
}
