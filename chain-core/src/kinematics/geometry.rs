//! Small fixed-size 3-D helpers shared by the kinematics solvers: vectors and
//! row-major 3×3 matrices as plain arrays (the hot paths of the inverse
//! kinematics keep them on the stack and inline), rotations about an axis
//! (Rodrigues) and the rotation-vector logarithm.

/// A 3-vector.
pub type V3 = [f64; 3];
/// A row-major 3×3 matrix.
pub type M3 = [[f64; 3]; 3];

/// `a · b`.
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// `|a|`.
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
/// `s a`.
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// `a − b`.
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// `a × b`.
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
/// Column `j` of `r`.
pub fn col(r: &M3, j: usize) -> V3 {
    [r[0][j], r[1][j], r[2][j]]
}
/// `a b`.
pub fn mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}
/// `aᵀ`.
pub fn tr(a: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}
/// `a x`.
pub fn mat_vec(a: &M3, x: V3) -> V3 {
    [dot(a[0], x), dot(a[1], x), dot(a[2], x)]
}
/// `aᵀ x`.
pub fn mul_t_vec(a: &M3, x: V3) -> V3 {
    mat_vec(&tr(a), x)
}
/// `det a`.
pub fn det(a: &M3) -> f64 {
    dot(a[0], cross(a[1], a[2]))
}
/// Solves `a x = y` by Cramer's rule; `None` when `|det a| < 1e-12`.
pub fn solve3(a: &M3, y: V3) -> Option<V3> {
    let d = det(a);
    if d.abs() < 1e-12 {
        return None;
    }
    let c = tr(a);
    Some([
        dot(y, cross(c[1], c[2])) / d,
        dot(c[0], cross(y, c[2])) / d,
        dot(c[0], cross(c[1], y)) / d,
    ])
}
/// The axis of a rotation by +π/2.
pub fn quarter_axis(r: &M3) -> V3 {
    [
        (r[2][1] - r[1][2]) / 2.0,
        (r[0][2] - r[2][0]) / 2.0,
        (r[1][0] - r[0][1]) / 2.0,
    ]
}
/// The rotation by `a` about the unit axis `u`.
pub fn rodrigues(u: V3, a: f64) -> M3 {
    let columns = [
        rodrigues_vec(u, a, [1.0, 0.0, 0.0]),
        rodrigues_vec(u, a, [0.0, 1.0, 0.0]),
        rodrigues_vec(u, a, [0.0, 0.0, 1.0]),
    ];
    std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i]))
}
/// `x` rotated by `a` about the unit axis `u`.
pub fn rodrigues_vec(u: V3, a: f64, x: V3) -> V3 {
    let (s, c) = a.sin_cos();
    let ux = cross(u, x);
    let ud = dot(u, x) * (1.0 - c);
    [
        x[0] * c + ux[0] * s + u[0] * ud,
        x[1] * c + ux[1] * s + u[1] * ud,
        x[2] * c + ux[2] * s + u[2] * ud,
    ]
}

/// Two unit vectors completing `z` to an orthonormal basis.
pub fn basis(z: V3) -> (V3, V3) {
    let n = norm(z);
    let z = [z[0] / n, z[1] / n, z[2] / n];
    let helper = if z[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = cross(z, helper);
    let l = norm(e1);
    let e1 = [e1[0] / l, e1[1] / l, e1[2] / l];
    (e1, cross(z, e1))
}

/// The rotation vector `θ·u` of a rotation matrix (`θ ∈ [0, π]`).
pub fn log_so3(r: &M3) -> V3 {
    let w = [
        0.5 * (r[2][1] - r[1][2]),
        0.5 * (r[0][2] - r[2][0]),
        0.5 * (r[1][0] - r[0][1]),
    ];
    let c = (0.5 * (r[0][0] + r[1][1] + r[2][2] - 1.0)).clamp(-1.0, 1.0);
    let s = norm(w);
    let theta = s.atan2(c);
    if s < 1e-300 && c > 0.0 {
        return [0.0; 3];
    }
    if theta < 3.0 {
        let k = theta / s;
        return [k * w[0], k * w[1], k * w[2]];
    }
    // Near π: the axis from the symmetric part, its sign from w.
    let b: M3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| 0.5 * (r[i][j] + r[j][i]) - if i == j { c } else { 0.0 })
    });
    let k = (0..3)
        .max_by(|&i, &j| b[i][i].total_cmp(&b[j][j]))
        .unwrap_or(0);
    let mut u = col(&b, k);
    let l = norm(u);
    if l == 0.0 {
        return [theta, 0.0, 0.0];
    }
    u = [u[0] / l, u[1] / l, u[2] / l];
    if dot(u, w) < 0.0 {
        u = [-u[0], -u[1], -u[2]];
    }
    [theta * u[0], theta * u[1], theta * u[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_inverts_the_rotation_up_to_pi() {
        let n = norm([0.3, -0.5, 0.8]);
        let u = scale([0.3, -0.5, 0.8], 1.0 / n);
        for &a in &[0.0, 1e-9, 0.3, 2.9, 3.05, 3.1, std::f64::consts::PI - 1e-9] {
            let w = log_so3(&rodrigues(u, a));
            for i in 0..3 {
                assert!((w[i] - a * u[i]).abs() < 1e-7, "{a}: {w:?}");
            }
        }
    }

    #[test]
    fn cramer_and_rodrigues() {
        let a = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = solve3(&a, [3.0, 7.0, 13.0]).unwrap();
        for (xi, want) in x.iter().zip([1.0, 1.0, 3.0]) {
            assert!((xi - want).abs() < 1e-14, "{x:?}");
        }
        let r = rodrigues([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
        assert!((r[0][1] + 1.0).abs() < 1e-15 && (r[1][0] - 1.0).abs() < 1e-15);
        assert!((det(&r) - 1.0).abs() < 1e-15);
    }
}
