//! Numbers from fuzzer bytes. Reading past the end gives zeros, so every input is usable and
//! libFuzzer's mutations of one byte change one decision.

/// Values that break numerical code, each one byte away.
pub const AWKWARD: [f64; 20] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e308,
    -1e308,
    1e-308,
    5e-324,
    -5e-324,
    f64::MIN_POSITIVE,
    f64::MAX,
    f64::MIN,
    f64::EPSILON,
    1e-300,
    1e300,
    0.5,
    std::f64::consts::PI,
];

/// The largest finite magnitude [`Input::any_f64`] produces: `FUZZ_MAX_MAGNITUDE` from the
/// environment (e.g. `1e100`, so that products of a few inputs cannot overflow), or
/// `f64::MAX` when it is not set.
pub fn magnitude_cap() -> f64 {
    static CAP: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *CAP.get_or_init(|| {
        std::env::var("FUZZ_MAX_MAGNITUDE")
            .ok()
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|c| *c > 0.0)
            .unwrap_or(f64::MAX)
    })
}

/// A cursor over the fuzzer's bytes.
pub struct Input<'a> {
    bytes: &'a [u8],
}

impl<'a> Input<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Input { bytes }
    }

    /// Whether every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    pub fn u8(&mut self) -> u8 {
        match self.bytes.split_first() {
            Some((&b, rest)) => {
                self.bytes = rest;
                b
            }
            None => 0,
        }
    }

    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    pub fn u64(&mut self) -> u64 {
        let mut b = [0u8; 8];
        for byte in &mut b {
            *byte = self.u8();
        }
        u64::from_le_bytes(b)
    }

    pub fn bool(&mut self) -> bool {
        self.u8() & 1 == 1
    }

    /// An integer in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { usize::from(self.u16()) % n }
    }

    /// Any double: one of [`AWKWARD`], a raw bit pattern, or a small decimal m·10^e with
    /// |m| < 2^15 and |e| ≤ 40, chosen by the first byte. Finite values above
    /// [`magnitude_cap`] are clamped to it (NaN, ±∞ and subnormals pass).
    pub fn any_f64(&mut self) -> f64 {
        let selector = self.u8();
        let x = match selector % 8 {
            0 => AWKWARD[usize::from(selector / 8) % AWKWARD.len()],
            1 => f64::from_bits(self.u64()),
            _ => self.decimal(40),
        };
        let cap = magnitude_cap();
        if x.is_finite() && x.abs() > cap {
            cap.copysign(x)
        } else {
            x
        }
    }

    /// A finite double of moderate size: m·10^e with |m| < 2^15 and |e| ≤ `max_exponent`.
    pub fn decimal(&mut self, max_exponent: i32) -> f64 {
        let mantissa = f64::from(self.u16() as i16);
        let span = 2 * max_exponent + 1;
        let exponent = i32::from(self.u8()) % span - max_exponent;
        mantissa * 10f64.powi(exponent) / 1024.0
    }

    /// A finite double in [−scale, scale].
    pub fn moderate(&mut self, scale: f64) -> f64 {
        let m = f64::from(self.u16() as i16) / 32768.0;
        m * scale
    }

    /// A finite double in [0, 1].
    pub fn fraction(&mut self) -> f64 {
        f64::from(self.u16()) / f64::from(u16::MAX)
    }

    pub fn vec3_any(&mut self) -> [f64; 3] {
        [self.any_f64(), self.any_f64(), self.any_f64()]
    }

    pub fn vec3_moderate(&mut self, scale: f64) -> [f64; 3] {
        [self.moderate(scale), self.moderate(scale), self.moderate(scale)]
    }

    /// A unit quaternion (w, x, y, z), normalised from moderate components (the identity if
    /// they are all zero).
    pub fn unit_quaternion(&mut self) -> [f64; 4] {
        let q = [
            self.moderate(1.0),
            self.moderate(1.0),
            self.moderate(1.0),
            self.moderate(1.0),
        ];
        let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        if norm < 1e-3 {
            [1.0, 0.0, 0.0, 0.0]
        } else {
            q.map(|c| c / norm)
        }
    }

    /// An enum integer: mostly one of the `valid` values 0..valid, sometimes any i32.
    pub fn enum_i32(&mut self, valid: i32) -> i32 {
        let selector = self.u8();
        if selector < 240 {
            i32::from(selector) % valid.max(1)
        } else {
            self.u64() as i32
        }
    }

    /// A 3×3 matrix (column-major): a rotation, a rotation with one entry nudged by a few
    /// ulps or by a visible amount, or nine arbitrary doubles.
    pub fn mat3(&mut self) -> [f64; 9] {
        match self.u8() % 4 {
            0 | 1 => rotation_of(self.unit_quaternion()),
            2 => {
                let mut r = rotation_of(self.unit_quaternion());
                let k = self.below(9);
                r[k] += self.decimal(20) * 1e-12;
                r
            }
            _ => std::array::from_fn(|_| self.any_f64()),
        }
    }

    /// A unit vector, normalised from moderate components (x̂ if they are all tiny).
    pub fn unit_vec3(&mut self) -> [f64; 3] {
        let v = self.vec3_moderate(1.0);
        let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if norm < 1e-3 {
            [1.0, 0.0, 0.0]
        } else {
            v.map(|c| c / norm)
        }
    }
}

/// The column-major rotation matrix of a unit quaternion (w, x, y, z).
pub fn rotation_of(q: [f64; 4]) -> [f64; 9] {
    let [w, x, y, z] = q;
    [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y + w * z),
        2.0 * (x * z - w * y),
        2.0 * (x * y - w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z + w * x),
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        1.0 - 2.0 * (x * x + y * y),
    ]
}

/// R·v for a column-major 3×3 matrix.
pub fn mat_vec(r: &[f64; 9], v: [f64; 3]) -> [f64; 3] {
    [
        r[0] * v[0] + r[3] * v[1] + r[6] * v[2],
        r[1] * v[0] + r[4] * v[1] + r[7] * v[2],
        r[2] * v[0] + r[5] * v[1] + r[8] * v[2],
    ]
}

/// R·J·Rᵀ for column-major 3×3 matrices.
pub fn rotate_tensor(r: &[f64; 9], j: &[f64; 9]) -> [f64; 9] {
    let mut out = [0.0; 9];
    for row in 0..3 {
        for col in 0..3 {
            let mut sum = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    sum += r[row + 3 * a] * j[a + 3 * b] * r[col + 3 * b];
                }
            }
            out[row + 3 * col] = sum;
        }
    }
    out
}
