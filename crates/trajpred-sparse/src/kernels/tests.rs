//! Tests of the dense kernels against plain loops.
use super::*;

fn matrix(n: usize, p: usize) -> Vec<f64> {
    (0..n * p)
        .map(|k| ((k * 7919 % 1013) as f64 - 506.0) / 97.0)
        .collect()
}

fn naive_dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn kernels_agree_with_plain_loops_on_awkward_sizes() {
    // sizes around the vector widths, the four-column groups and the row panels
    for &(n, p) in &[
        (1, 1),
        (3, 2),
        (17, 5),
        (31, 9),
        (64, 4),
        (515, 7),
        (1030, 13),
        (300, 29),
    ] {
        let x = matrix(n, p);
        let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let cols: Vec<usize> = (0..p).rev().collect();
        let mut out = vec![0.0; p];
        dots(&x, n, &cols, &v, &mut out);
        for (k, &j) in cols.iter().enumerate() {
            let want = naive_dot(&x[j * n..(j + 1) * n], &v);
            assert!(close(out[k], want), "dots {n}x{p} col {j}");
            assert!(close(dot(&x[j * n..(j + 1) * n], &v), want), "dot {n}x{p}");
        }
        let w: Vec<f64> = (0..p).map(|k| 1.0 - 0.3 * k as f64).collect();
        let mut u = vec![f64::NAN; n];
        combine(&x, n, &cols, &w, &mut u);
        for i in 0..n {
            let want: f64 = cols.iter().zip(&w).map(|(&j, wk)| wk * x[j * n + i]).sum();
            assert!(close(u[i], want), "combine {n}x{p} row {i}");
        }
        let b: Vec<f64> = (0..p).map(|k| 0.25 * k as f64 - 0.5).collect();
        let mut rd = vec![f64::NAN; p];
        residual_dots(&x, n, &cols, &b, &v, &mut rd);
        let resid: Vec<f64> = (0..n)
            .map(|i| {
                v[i] - cols
                    .iter()
                    .zip(&b)
                    .map(|(&j, bk)| bk * x[j * n + i])
                    .sum::<f64>()
            })
            .collect();
        for (k, &j) in cols.iter().enumerate() {
            let want = naive_dot(&x[j * n..(j + 1) * n], &resid);
            assert!(
                (rd[k] - want).abs() <= 1e-10 * (1.0 + want.abs()),
                "residual_dots {n}x{p} col {j}: {} vs {want}",
                rd[k]
            );
        }
        let (g, ld, xtv) = gram(&x, n, p, &v);
        let g = g.as_slice();
        for j in 0..p {
            let want = naive_dot(&x[j * n..(j + 1) * n], &v);
            assert!(close(xtv[j], want), "gram X^T v {n}x{p} col {j}");
        }
        for i in 0..p {
            for j in 0..p {
                let want = naive_dot(&x[i * n..(i + 1) * n], &x[j * n..(j + 1) * n]);
                assert!(close(g[j * ld + i], want), "gram {n}x{p} ({i}, {j})");
            }
        }
    }
}

#[test]
fn column_kernels_read_rows_below_a_longer_column_stride() {
    // columns of `n` rows stored `ld` apart (an aligned copy pads them): the padding, filled
    // with NaN here, must never be read, and the results are those of the unpadded matrix
    for &(n, p, ld) in &[(3, 2, 8), (17, 5, 24), (200, 9, 200), (515, 7, 520)] {
        let x = matrix(n, p);
        let mut padded = vec![f64::NAN; ld * p];
        for j in 0..p {
            padded[j * ld..j * ld + n].copy_from_slice(&x[j * n..(j + 1) * n]);
        }
        let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let cols: Vec<usize> = (0..p).rev().collect();
        let (mut got, mut want) = (vec![0.0; p], vec![0.0; p]);
        dots(&padded, ld, &cols, &v, &mut got);
        dots(&x, n, &cols, &v, &mut want);
        assert_eq!(got, want, "dots {n}x{p} ld {ld}");
        let w: Vec<f64> = (0..p).map(|k| 1.0 - 0.3 * k as f64).collect();
        let (mut got, mut want) = (vec![f64::NAN; n], vec![f64::NAN; n]);
        combine(&padded, ld, &cols, &w, &mut got);
        combine(&x, n, &cols, &w, &mut want);
        assert_eq!(got, want, "combine {n}x{p} ld {ld}");
        let (mut got, mut want) = (vec![f64::NAN; p], vec![f64::NAN; p]);
        residual_dots(&padded, ld, &cols, &w, &v, &mut got);
        residual_dots(&x, n, &cols, &w, &v, &mut want);
        assert_eq!(got, want, "residual_dots {n}x{p} ld {ld}");
    }
}

#[test]
fn packed_factor_rows_start_on_lines_and_do_not_overlap() {
    for i in 0..100 {
        let (o, next) = (tri_offset(i), tri_offset(i + 1));
        assert_eq!(o % 8, 0, "row {i} starts on a line");
        assert!(next > o + i, "row {i} fits before row {}", i + 1);
        assert!(next - o < i + 1 + 8, "row {i} wastes less than a line");
    }
}

#[test]
fn step_length_kernel_equals_the_plain_loop() {
    // lengths around the vector widths; signs, zeros, ties and a NaN in the correlations
    for len in [0usize, 1, 3, 7, 8, 9, 17, 64, 1001] {
        let c: Vec<f64> = (0..len)
            .map(|k| match k % 11 {
                0 => 0.0,
                5 => 2.0,  // |c| = C: one side has a zero numerator
                7 => -3.0, // |c| > C: one side has a negative numerator
                9 if len > 100 => f64::NAN,
                _ => ((k * 37 % 101) as f64 - 50.0) / 30.0,
            })
            .collect();
        let a: Vec<f64> = (0..len)
            .map(|k| match k % 13 {
                3 => 1.5, // a = AA: a zero denominator
                _ => ((k * 53 % 97) as f64 - 48.0) / 20.0,
            })
            .collect();
        for &(big_c, aa, gamma_hat) in &[
            (2.0, 1.5, 2.0 / 1.5),
            (2.0, 0.25, 8.0),
            (1e-3, 3.0, 1e-3 / 3.0),
        ] {
            let want = step::step_min_plain(&c, &a, big_c, aa, gamma_hat);
            let got = step_min(&c, &a, big_c, aa, gamma_hat);
            assert_eq!(got.to_bits(), want.to_bits(), "len {len} C {big_c} AA {aa}");
        }
    }
}

#[test]
fn two_vector_dots_equal_two_single_passes_bit_for_bit() {
    for &(n, p, ld) in &[
        (1, 1, 1),
        (3, 6, 8),
        (17, 5, 24),
        (200, 11, 200),
        (515, 9, 520),
    ] {
        let x = matrix(ld, p);
        let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let v2: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos() - 0.2).collect();
        let cols: Vec<usize> = (0..p).rev().collect();
        let (mut got, mut got2) = (vec![f64::NAN; p], vec![f64::NAN; p]);
        dots2(&x, ld, &cols, (&v, &v2), &mut got, &mut got2);
        let (mut want, mut want2) = (vec![0.0; p], vec![0.0; p]);
        dots(&x, ld, &cols, &v, &mut want);
        dots(&x, ld, &cols, &v2, &mut want2);
        let bits = |s: &[f64]| s.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&want), "v {n}x{p} ld {ld}");
        assert_eq!(bits(&got2), bits(&want2), "v2 {n}x{p} ld {ld}");
    }
}

#[test]
fn screen_bounds_kernel_equals_the_plain_loop() {
    // lengths around the vector widths; exact and uncertain terms, signs and zeros
    for len in [0usize, 1, 3, 5, 8, 9, 17, 64, 1001] {
        let c: Vec<f64> = (0..len)
            .map(|k| match k % 11 {
                0 => 0.0,
                5 => 2.0,
                7 => -3.0,
                _ => ((k * 37 % 101) as f64 - 50.0) / 30.0,
            })
            .collect();
        let a: Vec<f64> = (0..len)
            .map(|k| match k % 13 {
                3 => 1.5,
                _ => ((k * 53 % 97) as f64 - 48.0) / 20.0,
            })
            .collect();
        let e: Vec<f64> = (0..len).map(|k| [0.0, 1e-6, 0.3][k % 3]).collect();
        let b: Vec<f64> = (0..len).map(|k| [1e-5, 0.0, 0.2, 2.0][k % 4]).collect();
        for &(big_c, aa, gamma_hat) in &[(2.0, 1.5, 2.0 / 1.5), (2.0, 0.25, 8.0)] {
            let (mut lo, mut lo_plain) = (vec![f64::NAN; len], vec![f64::NAN; len]);
            let got = screen_bounds((&c, &a, &e, &b), (big_c, aa, gamma_hat), &mut lo);
            let want = screen_bounds_plain((&c, &a, &e, &b), (big_c, aa, gamma_hat), &mut lo_plain);
            assert_eq!(got.to_bits(), want.to_bits(), "len {len} C {big_c} AA {aa}");
            let bits = |s: &[f64]| s.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&lo), bits(&lo_plain), "len {len} C {big_c} AA {aa}");
        }
    }
}
