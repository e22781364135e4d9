// atan2, sin and cos in f64 (WGSL's built-ins are 32-bit), to a few ulps on the ranges the
// boundary kernel uses (arc angles in [0, π], parameters in [−π, π]).

// atan(z) for 0 ≤ z ≤ 1: three halvings of the angle, atan(z) = 2 atan(z / (1 + √(1 + z²))),
// bring z below tan(π/32) ≈ 0.0985, where the Taylor series to z¹⁹ is below 1e-19.
fn atan_unit(z0: real) -> real {
    var z = z0;
    for (var k = 0; k < 3; k++) {
        z = z / (1.0 + sqrt(1.0 + z * z));
    }
    let z2 = z * z;
    var term = z;
    var sum: real = 0.0;
    var sign: real = 1.0;
    for (var n = 0; n < 10; n++) {
        sum += sign * term / real(2 * n + 1);
        term *= z2;
        sign = -sign;
    }
    return 8.0 * sum;
}

fn atan2r(y: real, x: real) -> real {
    let ax = abs(x);
    let ay = abs(y);
    if ax == 0.0 && ay == 0.0 {
        return 0.0;
    }
    var a: real;
    if ay <= ax {
        a = atan_unit(ay / ax);
    } else {
        a = 0.5 * PI - atan_unit(ax / ay);
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 {
        a = -a;
    }
    return a;
}

// sin and cos of r for |r| ≤ π/4: Taylor series to r²¹ and r²⁰ (below 1e-19 there).
fn sin_small(r: real) -> real {
    let r2 = r * r;
    var term = r;
    var sum: real = 0.0;
    for (var n = 1; n <= 11; n++) {
        sum += term;
        term *= -r2 / real((2 * n) * (2 * n + 1));
    }
    return sum;
}

fn cos_small(r: real) -> real {
    let r2 = r * r;
    var term: real = 1.0;
    var sum: real = 0.0;
    for (var n = 1; n <= 11; n++) {
        sum += term;
        term *= -r2 / real((2 * n - 1) * (2 * n));
    }
    return sum;
}

// The quadrant k = round(t / (π/2)) and r = t − k π/2, |r| ≤ π/4.
fn sinr(t: real) -> real {
    let k = i32(round(t / (0.5 * PI)));
    let r = t - real(k) * (0.5 * PI);
    switch ((k % 4) + 4) % 4 {
        case 0: { return sin_small(r); }
        case 1: { return cos_small(r); }
        case 2: { return -sin_small(r); }
        default: { return -cos_small(r); }
    }
}

fn cosr(t: real) -> real {
    let k = i32(round(t / (0.5 * PI)));
    let r = t - real(k) * (0.5 * PI);
    switch ((k % 4) + 4) % 4 {
        case 0: { return cos_small(r); }
        case 1: { return -sin_small(r); }
        case 2: { return -cos_small(r); }
        default: { return sin_small(r); }
    }
}
