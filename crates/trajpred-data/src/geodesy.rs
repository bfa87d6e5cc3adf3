//! WGS84 geodesy: geodetic latitude/longitude/altitude to Earth-centred Earth-fixed (ECEF)
//! coordinates and to a local east-north-up (ENU) frame in metres around a reference point,
//! and back. Exact (through ECEF on the ellipsoid), not an equirectangular approximation.
//!
//! ```
//! use trajpred_data::geodesy::{Geodetic, LocalFrame};
//! let origin = Geodetic::new(39.9042, 116.4074, 50.0)?; // Beijing
//! let frame = LocalFrame::new(origin)?;
//! let p = Geodetic::new(39.9142, 116.4074, 50.0)?; // 0.01 deg further north
//! let enu = frame.to_enu(&p);
//! assert!(enu.east.abs() < 1e-6 && (enu.north - 1110.6).abs() < 1.0);
//! let back = frame.to_geodetic(&enu);
//! assert!((back.lat_deg - p.lat_deg).abs() < 1e-12);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, Result};

/// WGS84 semi-major axis a, metres.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84 flattening f.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS84 semi-minor axis b = a (1 - f), metres.
pub const WGS84_B: f64 = WGS84_A * (1.0 - WGS84_F);
/// First eccentricity squared e² = f (2 - f).
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);
/// Second eccentricity squared e'² = e² / (1 - e²).
pub const WGS84_EP2: f64 = WGS84_E2 / (1.0 - WGS84_E2);

/// Metres per international foot (GeoLife and ADS-B altitudes are in feet).
pub const FOOT: f64 = 0.3048;
/// Metres per second per knot (ADS-B ground speed).
pub const KNOT: f64 = 1852.0 / 3600.0;
/// Metres per second per foot-per-minute (ADS-B vertical rate).
pub const FOOT_PER_MINUTE: f64 = FOOT / 60.0;

/// A WGS84 geodetic position: latitude and longitude in degrees, height above the ellipsoid
/// in metres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Geodetic {
    /// Latitude, degrees, -90..=90.
    pub lat_deg: f64,
    /// Longitude, degrees (any finite value; -180..=180 from the conversions of this module).
    pub lon_deg: f64,
    /// Height above the WGS84 ellipsoid, metres.
    pub alt_m: f64,
}

impl Geodetic {
    /// A checked position: every value finite, latitude within ±90°, longitude within ±360°.
    pub fn new(lat_deg: f64, lon_deg: f64, alt_m: f64) -> Result<Self> {
        if !(lat_deg.is_finite() && (-90.0..=90.0).contains(&lat_deg)) {
            return Err(Error::param(
                "lat_deg",
                format!("must be in [-90, 90], got {lat_deg}"),
            ));
        }
        if !(lon_deg.is_finite() && (-360.0..=360.0).contains(&lon_deg)) {
            return Err(Error::param(
                "lon_deg",
                format!("must be in [-360, 360], got {lon_deg}"),
            ));
        }
        if !alt_m.is_finite() {
            return Err(Error::param(
                "alt_m",
                format!("must be finite, got {alt_m}"),
            ));
        }
        Ok(Geodetic {
            lat_deg,
            lon_deg,
            alt_m,
        })
    }
}

/// Earth-centred Earth-fixed Cartesian coordinates, metres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ecef {
    /// X: towards (0°N, 0°E).
    pub x: f64,
    /// Y: towards (0°N, 90°E).
    pub y: f64,
    /// Z: towards the north pole.
    pub z: f64,
}

/// Local east-north-up coordinates, metres, relative to a [`LocalFrame`]'s origin.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Enu {
    /// East, metres.
    pub east: f64,
    /// North, metres.
    pub north: f64,
    /// Up (along the ellipsoid normal at the origin), metres.
    pub up: f64,
}

/// Geodetic to ECEF: `N = a / sqrt(1 - e² sin² φ)`, `X = (N + h) cos φ cos λ`,
/// `Y = (N + h) cos φ sin λ`, `Z = (N (1 - e²) + h) sin φ`.
pub fn geodetic_to_ecef(g: &Geodetic) -> Ecef {
    let (sl, cl) = g.lat_deg.to_radians().sin_cos();
    let (so, co) = g.lon_deg.to_radians().sin_cos();
    let n = WGS84_A / (1.0 - WGS84_E2 * sl * sl).sqrt();
    Ecef {
        x: (n + g.alt_m) * cl * co,
        y: (n + g.alt_m) * cl * so,
        z: (n * (1.0 - WGS84_E2) + g.alt_m) * sl,
    }
}

/// ECEF to geodetic by Bowring's iteration on the parametric latitude, run to convergence
/// (at most 10 iterations; two suffice on and near the Earth to 1e-15 rad). The height uses
/// `h = p cos φ + z sin φ - a sqrt(1 - e² sin² φ)`, well conditioned at the poles too.
pub fn ecef_to_geodetic(e: &Ecef) -> Geodetic {
    let p = e.x.hypot(e.y);
    let lon = e.y.atan2(e.x);
    if p == 0.0 && e.z == 0.0 {
        // the centre of the Earth: any latitude; report the equator
        return Geodetic {
            lat_deg: 0.0,
            lon_deg: lon.to_degrees(),
            alt_m: -WGS84_A,
        };
    }
    let mut beta = e.z.atan2((1.0 - WGS84_F) * p);
    let mut lat = 0.0;
    for _ in 0..10 {
        let (sb, cb) = beta.sin_cos();
        lat =
            (e.z + WGS84_EP2 * WGS84_B * sb * sb * sb).atan2(p - WGS84_E2 * WGS84_A * cb * cb * cb);
        let next = ((1.0 - WGS84_F) * lat.sin()).atan2(lat.cos());
        let done = (next - beta).abs() < 1e-15;
        beta = next;
        if done {
            break;
        }
    }
    let (sl, cl) = lat.sin_cos();
    let alt = p * cl + e.z * sl - WGS84_A * (1.0 - WGS84_E2 * sl * sl).sqrt();
    Geodetic {
        lat_deg: lat.to_degrees(),
        lon_deg: lon.to_degrees(),
        alt_m: alt,
    }
}

/// A local east-north-up tangent frame at a reference point (the origin), for converting
/// positions to metres and back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    origin: Geodetic,
    origin_ecef: Ecef,
    sin_lat: f64,
    cos_lat: f64,
    sin_lon: f64,
    cos_lon: f64,
}

impl LocalFrame {
    /// The ENU frame at `origin` (checked like [`Geodetic::new`]).
    pub fn new(origin: Geodetic) -> Result<Self> {
        let origin = Geodetic::new(origin.lat_deg, origin.lon_deg, origin.alt_m)?;
        let (sin_lat, cos_lat) = origin.lat_deg.to_radians().sin_cos();
        let (sin_lon, cos_lon) = origin.lon_deg.to_radians().sin_cos();
        Ok(LocalFrame {
            origin,
            origin_ecef: geodetic_to_ecef(&origin),
            sin_lat,
            cos_lat,
            sin_lon,
            cos_lon,
        })
    }

    /// The reference point.
    pub fn origin(&self) -> Geodetic {
        self.origin
    }

    /// ECEF to ENU: rotate the difference from the origin's ECEF position.
    pub fn ecef_to_enu(&self, p: &Ecef) -> Enu {
        let dx = p.x - self.origin_ecef.x;
        let dy = p.y - self.origin_ecef.y;
        let dz = p.z - self.origin_ecef.z;
        let t = self.cos_lon * dx + self.sin_lon * dy;
        Enu {
            east: -self.sin_lon * dx + self.cos_lon * dy,
            north: -self.sin_lat * t + self.cos_lat * dz,
            up: self.cos_lat * t + self.sin_lat * dz,
        }
    }

    /// ENU to ECEF (the transpose rotation, plus the origin).
    pub fn enu_to_ecef(&self, p: &Enu) -> Ecef {
        let t = -self.sin_lat * p.north + self.cos_lat * p.up;
        Ecef {
            x: self.origin_ecef.x - self.sin_lon * p.east + self.cos_lon * t,
            y: self.origin_ecef.y + self.cos_lon * p.east + self.sin_lon * t,
            z: self.origin_ecef.z + self.cos_lat * p.north + self.sin_lat * p.up,
        }
    }

    /// Geodetic to ENU metres.
    pub fn to_enu(&self, g: &Geodetic) -> Enu {
        self.ecef_to_enu(&geodetic_to_ecef(g))
    }

    /// ENU metres to geodetic.
    pub fn to_geodetic(&self, p: &Enu) -> Geodetic {
        ecef_to_geodetic(&self.enu_to_ecef(p))
    }
}
