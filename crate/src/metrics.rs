//! The field's text-to-motion metrics (Guo et al. 2022's protocol), computed on evaluator
//! embeddings: R-precision, FID, MM-Dist, diversity and multimodality, and the mean ± 95 %
//! interval over repeated runs.
//!
//! Every function takes embeddings as rows of equal length (the evaluator's joint space) and
//! measures Euclidean distances between them, as the protocol does.

use crate::rng::Rng;

/// Euclidean distance between two embeddings.
pub fn distance(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// R-precision top-1, top-2 and top-3: rows are cut into consecutive batches of `batch`
/// (text `i` belongs with motion `i`); within a batch, each text ranks all the batch's
/// motions by distance, and a hit at `k` means its own motion is among the `k` nearest. The
/// rates are averaged over all texts of full batches (a last, partial batch is dropped, as in
/// the protocol). Ties count against the text.
pub fn r_precision(texts: &[Vec<f32>], motions: &[Vec<f32>], batch: usize) -> [f64; 3] {
    let ranks: Vec<usize> = batch_ranks(texts, motions, batch)
        .into_iter()
        .flatten()
        .collect();
    let mut hits = [0usize; 3];
    for nearer in &ranks {
        for (k, hit) in hits.iter_mut().enumerate() {
            if *nearer <= k {
                *hit += 1;
            }
        }
    }
    hits.map(|h| h as f64 / ranks.len().max(1) as f64)
}

/// For each text, how many other motions of its batch of `batch` are at least as near to it
/// as its own motion (0 = its own motion ranks first); `None` for texts past the last whole
/// batch, which R-precision leaves out.
pub fn batch_ranks(texts: &[Vec<f32>], motions: &[Vec<f32>], batch: usize) -> Vec<Option<usize>> {
    assert_eq!(texts.len(), motions.len(), "one motion per text");
    let mut ranks = vec![None; texts.len()];
    for start in (0..texts.len()).step_by(batch.max(1)) {
        let end = start + batch;
        if end > texts.len() {
            break;
        }
        for i in start..end {
            let own = distance(&texts[i], &motions[i]);
            let nearer = (start..end)
                .filter(|&j| j != i && distance(&texts[i], &motions[j]) <= own)
                .count();
            ranks[i] = Some(nearer);
        }
    }
    ranks
}

/// MM-Dist: the mean distance between each text and its own motion.
pub fn mm_dist(texts: &[Vec<f32>], motions: &[Vec<f32>]) -> f64 {
    assert_eq!(texts.len(), motions.len(), "one motion per text");
    let total: f64 = texts.iter().zip(motions).map(|(t, m)| distance(t, m)).sum();
    total / texts.len().max(1) as f64
}

/// Diversity: the mean distance between `pairs` random pairs of motions (two random index
/// draws, as the protocol's 300 pairs).
pub fn diversity(motions: &[Vec<f32>], pairs: usize, rng: &mut Rng) -> f64 {
    if motions.len() < 2 || pairs == 0 {
        return 0.0;
    }
    let total: f64 = (0..pairs)
        .map(|_| {
            let a = rng.below(motions.len());
            let b = rng.below(motions.len());
            distance(&motions[a], &motions[b])
        })
        .sum();
    total / pairs as f64
}

/// Multimodality: for each text's group of motions generated from it, the mean distance
/// between `pairs` random pairs within the group, averaged over groups.
pub fn multimodality(groups: &[Vec<Vec<f32>>], pairs: usize, rng: &mut Rng) -> f64 {
    let scores: Vec<f64> = groups
        .iter()
        .filter(|g| g.len() >= 2)
        .map(|g| diversity(g, pairs, rng))
        .collect();
    scores.iter().sum::<f64>() / scores.len().max(1) as f64
}

/// Fréchet distance between Gaussians fitted to two sets of embeddings:
/// ‖μ₁ − μ₂‖² + Tr(Σ₁ + Σ₂ − 2 (Σ₁Σ₂)^½).
pub fn fid(a: &[Vec<f32>], b: &[Vec<f32>]) -> f64 {
    let (mu_a, cov_a) = gaussian(a);
    let (mu_b, cov_b) = gaussian(b);
    let mean_term: f64 = mu_a.iter().zip(&mu_b).map(|(x, y)| (x - y).powi(2)).sum();
    let d = mu_a.len();
    let trace = |m: &[f64]| (0..d).map(|i| m[i * d + i]).sum::<f64>();
    // Tr((Σ₁Σ₂)^½) = Tr((Σ₁^½ Σ₂ Σ₁^½)^½), whose argument is symmetric positive semi-definite.
    let root_a = symmetric_sqrt(&cov_a, d);
    let inner = matmul(&matmul(&root_a, &cov_b, d), &root_a, d);
    let (values, _) = symmetric_eigen(&inner, d);
    let cross: f64 = values.iter().map(|v| v.max(0.0).sqrt()).sum();
    (mean_term + trace(&cov_a) + trace(&cov_b) - 2.0 * cross).max(0.0)
}

/// Mean and (population-normalised, n − 1) covariance of rows, row-major `d × d`.
fn gaussian(rows: &[Vec<f32>]) -> (Vec<f64>, Vec<f64>) {
    let n = rows.len();
    let d = rows.first().map_or(0, Vec::len);
    let mut mean = vec![0.0; d];
    for r in rows {
        for (m, x) in mean.iter_mut().zip(r) {
            *m += *x as f64 / n as f64;
        }
    }
    let mut cov = vec![0.0; d * d];
    for r in rows {
        let c: Vec<f64> = r.iter().zip(&mean).map(|(x, m)| *x as f64 - m).collect();
        for i in 0..d {
            for j in i..d {
                cov[i * d + j] += c[i] * c[j];
            }
        }
    }
    let norm = (n.max(2) - 1) as f64;
    for i in 0..d {
        for j in i..d {
            cov[i * d + j] /= norm;
            cov[j * d + i] = cov[i * d + j];
        }
    }
    (mean, cov)
}

fn matmul(a: &[f64], b: &[f64], d: usize) -> Vec<f64> {
    let mut out = vec![0.0; d * d];
    for i in 0..d {
        for k in 0..d {
            let x = a[i * d + k];
            if x != 0.0 {
                for j in 0..d {
                    out[i * d + j] += x * b[k * d + j];
                }
            }
        }
    }
    out
}

/// V·diag(√λ)·Vᵀ of a symmetric positive semi-definite matrix.
fn symmetric_sqrt(m: &[f64], d: usize) -> Vec<f64> {
    let (values, vectors) = symmetric_eigen(m, d);
    let mut out = vec![0.0; d * d];
    for (k, value) in values.iter().enumerate() {
        let s = value.max(0.0).sqrt();
        for i in 0..d {
            let vik = vectors[i * d + k] * s;
            for j in 0..d {
                out[i * d + j] += vik * vectors[j * d + k];
            }
        }
    }
    out
}

/// Eigenvalues and eigenvectors (as columns, row-major) of a symmetric matrix by cyclic Jacobi
/// rotations: slow for large matrices, exact enough and dependency-free for the evaluator's
/// few hundred dimensions.
fn symmetric_eigen(m: &[f64], d: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = m.to_vec();
    let mut v = vec![0.0; d * d];
    for i in 0..d {
        v[i * d + i] = 1.0;
    }
    let scale: f64 = a
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    for _sweep in 0..100 {
        let off: f64 = (0..d)
            .flat_map(|i| (0..d).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * d + j].powi(2))
            .sum::<f64>()
            .sqrt();
        if off <= 1e-13 * scale {
            break;
        }
        for p in 0..d {
            for q in p + 1..d {
                let apq = a[p * d + q];
                if apq.abs() <= 1e-300 {
                    continue;
                }
                let theta = (a[q * d + q] - a[p * d + p]) / (2.0 * apq);
                let sign = if theta >= 0.0 { 1.0 } else { -1.0 };
                let t = sign / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..d {
                    let akp = a[k * d + p];
                    let akq = a[k * d + q];
                    a[k * d + p] = c * akp - s * akq;
                    a[k * d + q] = s * akp + c * akq;
                }
                for k in 0..d {
                    let apk = a[p * d + k];
                    let aqk = a[q * d + k];
                    a[p * d + k] = c * apk - s * aqk;
                    a[q * d + k] = s * apk + c * aqk;
                }
                for k in 0..d {
                    let vkp = v[k * d + p];
                    let vkq = v[k * d + q];
                    v[k * d + p] = c * vkp - s * vkq;
                    v[k * d + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..d).map(|i| a[i * d + i]).collect(), v)
}

/// A figure over repeated runs: the mean and the half-width of its 95 % confidence interval
/// (1.96 standard errors, as the field reports).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Interval {
    pub mean: f64,
    pub ci95: f64,
}

impl Interval {
    /// The interval of repeated measurements.
    pub fn of(values: &[f64]) -> Interval {
        let n = values.len().max(1) as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = if values.len() > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        Interval {
            mean,
            ci95: 1.96 * (var / n).sqrt(),
        }
    }
}

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.3} ± {:.3}", self.mean, self.ci95)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_rows(n: usize, d: usize, seed: u64) -> Vec<Vec<f32>> {
        let mut rng = Rng::new(seed);
        (0..n)
            .map(|_| (0..d).map(|_| rng.normal()).collect())
            .collect()
    }

    #[test]
    fn fid_of_a_set_with_itself_is_zero_and_a_shift_adds_its_square() {
        let a = random_rows(400, 16, 1);
        assert!(fid(&a, &a).abs() < 1e-6, "{}", fid(&a, &a));
        let shifted: Vec<Vec<f32>> = a
            .iter()
            .map(|r| r.iter().map(|x| x + 0.5).collect())
            .collect();
        // Same covariance, means 0.5 apart in each of 16 dimensions: 16 × 0.25.
        assert!(
            (fid(&a, &shifted) - 4.0).abs() < 1e-6,
            "{}",
            fid(&a, &shifted)
        );
    }

    #[test]
    fn fid_matches_the_closed_form_for_scaled_gaussians() {
        // Σ₂ = s²Σ₁: Tr(Σ₁ + s²Σ₁ − 2sΣ₁) = (1 − s)² Tr Σ₁.
        let a = random_rows(300, 8, 2);
        let scaled: Vec<Vec<f32>> = a
            .iter()
            .map(|r| r.iter().map(|x| x * 3.0).collect())
            .collect();
        let (_, cov) = gaussian(&a);
        let trace: f64 = (0..8).map(|i| cov[i * 8 + i]).sum();
        let (mean, _) = gaussian(&a);
        let mean_shift: f64 = mean.iter().map(|m| (2.0 * m).powi(2)).sum();
        let expected = 4.0 * trace + mean_shift;
        let got = fid(&a, &scaled);
        assert!(
            (got - expected).abs() < 1e-6 * expected,
            "{got} vs {expected}"
        );
    }

    #[test]
    fn jacobi_reconstructs_a_symmetric_matrix() {
        let rows = random_rows(50, 6, 3);
        let (_, cov) = gaussian(&rows);
        let root = symmetric_sqrt(&cov, 6);
        let back = matmul(&root, &root, 6);
        for (x, y) in back.iter().zip(&cov) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
    }

    #[test]
    fn a_perfect_matcher_has_r_precision_one_and_a_constant_one_has_the_chance_floor() {
        let texts = random_rows(64, 8, 4);
        assert_eq!(r_precision(&texts, &texts, 32), [1.0, 1.0, 1.0]);
        assert_eq!(mm_dist(&texts, &texts), 0.0);
        // All motions alike: every motion ties with the text's own, so nothing is a hit.
        let same = vec![vec![0.0f32; 8]; 64];
        assert_eq!(r_precision(&texts, &same, 32), [0.0, 0.0, 0.0]);
        // A partial last batch is dropped.
        assert_eq!(r_precision(&texts[..40], &texts[..40], 32), [1.0, 1.0, 1.0]);
        let ranks = batch_ranks(&texts[..40], &texts[..40], 32);
        assert_eq!(ranks.iter().filter(|r| **r == Some(0)).count(), 32);
        assert!(ranks[32..].iter().all(Option::is_none));
    }

    #[test]
    fn r_precision_counts_ranks() {
        let texts = vec![vec![0.0f32], vec![100.0], vec![200.0]];
        // Text 0 has motions 1 and 2 nearer than its own (rank 3), text 1 is matched
        // (rank 1), text 2 has motion 0 nearer (rank 2).
        let motions = vec![vec![150.0f32], vec![90.0], vec![120.0]];
        let [top1, top2, top3] = r_precision(&texts, &motions, 3);
        assert!((top1 - 1.0 / 3.0).abs() < 1e-12, "{top1}");
        assert!((top2 - 2.0 / 3.0).abs() < 1e-12, "{top2}");
        assert_eq!(top3, 1.0);
    }

    #[test]
    fn diversity_of_identical_motions_is_zero_and_grows_with_spread() {
        let mut rng = Rng::new(5);
        let same = vec![vec![1.0f32, 2.0, 3.0]; 20];
        assert_eq!(diversity(&same, 300, &mut rng), 0.0);
        assert_eq!(multimodality(&[same.clone(), same], 10, &mut rng), 0.0);
        let spread = random_rows(200, 4, 6);
        let wide: Vec<Vec<f32>> = spread
            .iter()
            .map(|r| r.iter().map(|x| x * 2.0).collect())
            .collect();
        let d1 = diversity(&spread, 300, &mut Rng::new(7));
        let d2 = diversity(&wide, 300, &mut Rng::new(7));
        assert!((d2 - 2.0 * d1).abs() < 1e-9 && d1 > 1.0, "{d1} {d2}");
    }

    #[test]
    fn intervals_of_repeats() {
        assert_eq!(
            Interval::of(&[2.0, 2.0, 2.0]),
            Interval {
                mean: 2.0,
                ci95: 0.0
            }
        );
        let i = Interval::of(&[1.0, 3.0]);
        assert_eq!(i.mean, 2.0);
        // sd = √2, se = 1: 1.96.
        assert!((i.ci95 - 1.96).abs() < 1e-12);
    }
}
