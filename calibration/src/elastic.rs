//! The elastic contact of rigid indenters with a flat skin: the contact pressure on a grid of
//! square cells, the region where the skin touches the indenters, and the skin's surface
//! displaced everywhere, inside the contact (where it takes the indenter's shape) and round it
//! (where it sinks smoothly back to the undeformed plane). The skin is either a homogeneous
//! elastic half-space or an elastic layer bonded to a rigid base (a gel cast on its window:
//! 9DTact's 2.8 mm gel on acrylic), which is stiffer than a half-space once the contact is
//! not small against its thickness, and whose surface sinks over a length set by it.
//!
//! Sources:
//! - the surface's normal displacement under a uniform pressure `p` on a rectangle
//!   `|x| <= a, |y| <= b` of a half-space (Love, 1929; Johnson, Contact Mechanics, 1985,
//!   Eq. 3.25, Sec. 3.2): `u = p / (pi E*) [ (x + a) ln(...) + ... ]` below,
//!   `1 / E* = (1 - nu^2) / E` for a rigid indenter;
//! - the bonded layer: the surface displacement of a layer of thickness `h` on a rigid base,
//!   frictionless top, under the pressure's Fourier transform `p(k)`, is
//!   `u(k) = 2 / (E* k) K(kh) p(k)` with
//!   `K(t) = ((3 - 4 nu) sinh 2t - 2t) / ((3 - 4 nu) cosh 2t + 2t^2 + 5 - 12 nu + 8 nu^2)`
//!   ([`layer_factor`]: a pressure `cos(k x)` on the layer is a plane-strain problem along `k`;
//!   `K` is the solution of Navier's equations with `u = 0` on the base and no shear on the
//!   top, its closed form checked against a symbolic solution of the same equations), so that a point load's displacement is
//!   `u(r) = 1 / (pi E*) int_0^inf K(kh) J0(kr) dk`: the half-space's `1 / (pi E* r)` when
//!   `K = 1`. Its limits, checked in the tests: `K -> 1` for a thick layer; for a thin
//!   compressible one, `u = p h / M`, `M = E (1 - nu) / ((1 + nu)(1 - 2 nu))` (the constrained
//!   modulus: each column compressed on its own, a Winkler bed); for a thin incompressible
//!   one, `u = -h^3 / (3 mu) lap p` (the squeeze film of lubrication theory). A cell's
//!   influence is Love's rectangle plus the layer's smooth correction
//!   `1 / (pi E*) int_0^inf (K(kh) - 1) J0(kr) dk` (which decays as `e^(-2kh)` in `k`, so its
//!   integral converges; Bessel J0 from `libm`) summed over the cell by 3 x 3 Gauss points;
//! - the contact problem on the grid, `g = h + u - d >= 0`, `p >= 0`, `p g = 0` (`h` the
//!   indenter's height above its lowest point, `d` its approach), solved by the conjugate
//!   gradient of Polonsky and Keer (Wear 231, 1999, 206-219), for a given approach instead of a
//!   given load;
//! - the checks: a sphere on a half-space (Hertz; Johnson Sec. 4.2): contact radius
//!   `sqrt(R d)`, load `4/3 E* sqrt(R) d^1.5`, the profile of [`crate::press::hertz_depth_mm`];
//!   a paraboloid on a bonded layer against an axisymmetric solution of the same problem (a
//!   Fredholm equation, in the tests) and Garcia and Garcia's bottom-effect series (Biophys.
//!   J. 114, 2018, 2923-2932) for a bonded sample; a flat punch on a thin compressible layer
//!   against the constrained modulus.
//!
//! Lengths mm, pressures MPa (N/mm^2), loads N.

use rustfft::num_complex::Complex;

/// The skin the indenters press.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Skin {
    /// A homogeneous elastic half-space of effective modulus `E* = E / (1 - nu^2)`, MPa.
    HalfSpace { e_star_mpa: f64 },
    /// An elastic layer of `thickness_mm` bonded to a rigid base (a gel cast on its window),
    /// its top free of shear: Young's modulus, MPa, and Poisson's ratio in [0, 0.5].
    BondedLayer {
        young_mpa: f64,
        poisson: f64,
        thickness_mm: f64,
    },
}

impl Skin {
    /// The effective modulus `E / (1 - nu^2)` against a rigid indenter, MPa.
    pub fn e_star_mpa(&self) -> f64 {
        match *self {
            Skin::HalfSpace { e_star_mpa } => e_star_mpa,
            Skin::BondedLayer {
                young_mpa, poisson, ..
            } => young_mpa / (1.0 - poisson * poisson),
        }
    }
}

/// `K(t)`, the bonded layer's surface compliance against a half-space's at the wavenumber
/// `k = t / h` (`t` = wavenumber times thickness, `nu` Poisson's ratio): 1 for a thick layer,
/// `t (1 - 2 nu) / (2 (1 - nu)^2)` for a thin compressible one, `2 t^3 / 3` for a thin
/// incompressible one (module docs).
pub fn layer_factor(t: f64, nu: f64) -> f64 {
    1.0 + layer_factor_less_one(t, nu)
}

/// `K(t) - 1`, without the cancellation for large `t` (`-> 0` as `t^2 e^(-2t)`).
fn layer_factor_less_one(t: f64, nu: f64) -> f64 {
    let c = 3.0 - 4.0 * nu;
    let rest = 5.0 - 12.0 * nu + 8.0 * nu * nu;
    if t > 300.0 {
        return 0.0;
    }
    let e = (-2.0 * t).exp();
    // (c sinh 2t - 2t) - (c cosh 2t + 2t^2 + rest) = -c e^(-2t) - 2t - 2t^2 - rest
    let num = -c * e - 2.0 * t - 2.0 * t * t - rest;
    // divided through by e^(2t)
    let den = c * 0.5 * (1.0 + e * e) + (2.0 * t * t + rest) * e;
    num * e / den
}

/// A radial function tabulated at `0, dr, 2 dr, ...` up to `r_max_mm`:
/// `int_0^(40/h) f(k) J0(kr) dk` by Simpson's rule, fine enough for the oscillation of `J0`
/// at the farthest distance and for `f`'s decay over `k ~ 1 / h` (`f` below `1e-30` past
/// `k h = 40`: the layer's corrections here, which fall as `e^(-2kh)` or `e^(-k(2h - z))`).
struct HankelTable {
    dr: f64,
    values: Vec<f64>,
}

impl HankelTable {
    fn new(f: impl Fn(f64) -> f64, h: f64, dr: f64, r_max_mm: f64) -> HankelTable {
        use rayon::prelude::*;
        let k_max = 40.0 / h;
        let dk_wanted = (0.1 / r_max_mm.max(h)).min(0.02 / h);
        let mut steps = (k_max / dk_wanted).ceil() as usize;
        steps += steps % 2;
        let dk = k_max / steps as f64;
        let weights: Vec<(f64, f64)> = (0..=steps)
            .map(|i| {
                let k = i as f64 * dk;
                let w = if i == 0 || i == steps {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                (k, w * dk / 3.0 * f(k))
            })
            .collect();
        let count = (r_max_mm / dr).ceil() as usize + 2;
        let values = (0..count)
            .into_par_iter()
            .map(|j| {
                let r = j as f64 * dr;
                weights.iter().map(|&(k, w)| w * libm::j0(k * r)).sum()
            })
            .collect();
        HankelTable { dr, values }
    }

    /// The function at `r`, linear between the tabulated distances.
    fn at(&self, r: f64) -> f64 {
        let f = r / self.dr;
        let i = (f as usize).min(self.values.len() - 2);
        let w = f - i as f64;
        self.values[i] * (1.0 - w) + self.values[i + 1] * w
    }
}

/// The grid the pressure lives on: `n x n` square cells of side `cell_mm`, centred on the
/// origin of the skin's plane (cell `(i, j)` at `x = (i - (n - 1) / 2) cell_mm`, `y` alike).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGrid {
    pub n: usize,
    pub cell_mm: f64,
}

impl ContactGrid {
    /// The centre of cell `(i, j)` (column `i` along x, row `j` along y), mm.
    pub fn centre_mm(&self, i: usize, j: usize) -> (f64, f64) {
        let c = (self.n as f64 - 1.0) / 2.0;
        ((i as f64 - c) * self.cell_mm, (j as f64 - c) * self.cell_mm)
    }
}

/// The solved contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    pub grid: ContactGrid,
    /// Per cell (row-major, `j * n + i`): the pressure, MPa; the surface's displacement into
    /// the skin (positive down), mm; in contact (`p > 0`).
    pub pressure_mpa: Vec<f64>,
    pub displacement_mm: Vec<f64>,
    pub in_contact: Vec<bool>,
    /// The total load, N.
    pub load_n: f64,
    pub iterations: usize,
}

/// Why a contact cannot be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContactError {
    #[error("the grid must have 2 to {max} cells a side of a positive size: {n} x {cell_mm} mm")]
    Grid { n: usize, cell_mm: f64, max: usize },
    #[error("{0} indenter heights for {1} cells")]
    Heights(usize, usize),
    #[error("{name} = {value}: {rule}")]
    Value {
        name: &'static str,
        value: f64,
        rule: &'static str,
    },
    #[error("no convergence in {0} iterations (relative change {1:.2e})")]
    NoConvergence(usize, f64),
}

/// Most cells a side (each iteration convolves by FFTs of twice that size a side).
pub const MAX_CELLS: usize = 512;

/// The displacement at `(x, y)` of a unit pressure on the cell `|x'| <= a, |y'| <= a` times
/// `pi E*` (Love; Johnson Eq. 3.25).
fn love(x: f64, y: f64, a: f64) -> f64 {
    // ln(t + sqrt(s^2 + t^2)), without the cancellation for t < 0 (s != 0 there)
    let f = |s: f64, t: f64| -> f64 {
        let r = (s * s + t * t).sqrt();
        if t >= 0.0 {
            (t + r).ln()
        } else {
            (s * s / (r - t)).ln()
        }
    };
    let (xp, xm, yp, ym) = (x + a, x - a, y + a, y - a);
    let term = |u: f64, v1: f64, v2: f64| -> f64 {
        if u == 0.0 {
            0.0
        } else {
            u * (f(u, v1) - f(u, v2))
        }
    };
    term(xp, yp, ym) + term(yp, xp, xm) + term(xm, ym, yp) + term(ym, xm, xp)
}

/// Solves the contact of an indenter whose height above its lowest point at each cell is
/// `height_mm` (row-major, as [`Contact`]), pressed `approach_mm` into a half-space of
/// effective modulus `e_star_mpa` (`E / (1 - nu^2)` for a rigid indenter):
/// [`solve_skin_contact`] on [`Skin::HalfSpace`].
///
/// # Errors
/// As [`solve_skin_contact`].
pub fn solve_contact(
    grid: ContactGrid,
    height_mm: &[f64],
    approach_mm: f64,
    e_star_mpa: f64,
) -> Result<Contact, ContactError> {
    solve_skin_contact(grid, height_mm, approach_mm, Skin::HalfSpace { e_star_mpa })
}

/// Solves the contact of an indenter whose height above its lowest point at each cell is
/// `height_mm` (row-major, as [`Contact`]), pressed `approach_mm` into `skin`:
/// [`ContactSolver::new`] then [`ContactSolver::solve`].
///
/// # Errors
/// As theirs.
pub fn solve_skin_contact(
    grid: ContactGrid,
    height_mm: &[f64],
    approach_mm: f64,
    skin: Skin,
) -> Result<Contact, ContactError> {
    ContactSolver::new(grid, skin)?.solve(height_mm, approach_mm)
}

/// The contact solver of a skin on a grid: its influence, transformed once
/// ([`Convolver`]), for the presses of any indenters on that grid (a capture's frames).
///
/// The pressure lives where the indenters touch, a small part of the grid for a ball: the
/// conjugate gradient runs on a window round the cells the indenters overlap (two cells
/// more, by FFTs of the window's size), and the displacement over the whole grid is checked
/// once it converges: where the indenters would overlap the displaced skin outside the window,
/// the window grows to take those cells in and the solve is repeated (at most the whole grid).
/// The answer is the whole grid's (the contact problem has one solution), to the iteration's
/// tolerance.
pub struct ContactSolver {
    grid: ContactGrid,
    skin: Skin,
    /// The influence at every offset ([`influence`]).
    kernel: Vec<f64>,
    convolver: Convolver,
    /// The convolvers of the windows solved so far, by their size a side (few sizes: a
    /// window is as large as its FFTs allow).
    windows: std::sync::Mutex<std::collections::BTreeMap<usize, std::sync::Arc<Convolver>>>,
}

/// The cells a side the window keeps round the overlapped cells.
const WINDOW_MARGIN: usize = 2;

impl ContactSolver {
    /// The solver of `skin` on `grid`.
    ///
    /// # Errors
    /// [`ContactError`]: a grid out of range, a non-positive modulus, a Poisson's ratio
    /// outside [0, 0.5], a layer not thicker than two cells.
    pub fn new(grid: ContactGrid, skin: Skin) -> Result<ContactSolver, ContactError> {
        let n = grid.n;
        if let Skin::BondedLayer {
            young_mpa,
            poisson,
            thickness_mm,
        } = skin
        {
            if !(young_mpa.is_finite() && young_mpa > 0.0) {
                return Err(ContactError::Value {
                    name: "young_mpa",
                    value: young_mpa,
                    rule: "must be finite and > 0",
                });
            }
            if !(0.0..=0.5).contains(&poisson) {
                return Err(ContactError::Value {
                    name: "poisson",
                    value: poisson,
                    rule: "must be in [0, 0.5]",
                });
            }
            if !(thickness_mm.is_finite() && thickness_mm >= 2.0 * grid.cell_mm) {
                return Err(ContactError::Value {
                    name: "thickness_mm",
                    value: thickness_mm,
                    rule: "must be finite and at least two cells (the layer's correction is \
                       summed over each cell by Gauss points)",
                });
            }
        }
        let e_star_mpa = skin.e_star_mpa();
        if !((2..=MAX_CELLS).contains(&n) && grid.cell_mm.is_finite() && grid.cell_mm > 0.0) {
            return Err(ContactError::Grid {
                n,
                cell_mm: grid.cell_mm,
                max: MAX_CELLS,
            });
        }
        if !(e_star_mpa.is_finite() && e_star_mpa > 0.0) {
            return Err(ContactError::Value {
                name: "e_star_mpa",
                value: e_star_mpa,
                rule: "must be finite and > 0",
            });
        }
        let kernel = influence(grid, skin);
        Ok(ContactSolver {
            grid,
            skin,
            convolver: Convolver::new(n, &kernel),
            kernel,
            windows: Default::default(),
        })
    }

    /// The skin's grid.
    pub fn grid(&self) -> ContactGrid {
        self.grid
    }

    /// The skin.
    pub fn skin(&self) -> Skin {
        self.skin
    }

    /// The convolver of a `w x w` window (the kernel's offsets up to `w - 1`), made once.
    fn window_convolver(&self, w: usize) -> std::sync::Arc<Convolver> {
        let mut windows = self.windows.lock().unwrap_or_else(|e| e.into_inner());
        windows
            .entry(w)
            .or_insert_with(|| {
                let (n, m, mw) = (self.grid.n, 2 * self.grid.n - 1, 2 * w - 1);
                let mut crop = Vec::with_capacity(mw * mw);
                for dj in 0..mw {
                    let row = (dj + n - w) * m + (n - w);
                    crop.extend_from_slice(&self.kernel[row..row + mw]);
                }
                std::sync::Arc::new(Convolver::new(w, &crop))
            })
            .clone()
    }

    /// Solves the contact of an indenter whose height above its lowest point at each cell is
    /// `height_mm` (row-major, as [`Contact`]), pressed `approach_mm` into the skin.
    ///
    /// # Errors
    /// [`ContactError`]: heights of another count, a negative approach, no convergence.
    pub fn solve(&self, height_mm: &[f64], approach_mm: f64) -> Result<Contact, ContactError> {
        let (grid, n) = (self.grid, self.grid.n);
        if height_mm.len() != n * n {
            return Err(ContactError::Heights(height_mm.len(), n * n));
        }
        if !(approach_mm.is_finite() && approach_mm >= 0.0) {
            return Err(ContactError::Value {
                name: "approach_mm",
                value: approach_mm,
                rule: "must be finite and >= 0",
            });
        }
        // the cells to take in: those the indenter overlaps, then those it would overlap on
        // the displaced skin
        let mut take: Vec<usize> = (0..n * n).filter(|&k| height_mm[k] < approach_mm).collect();
        let mut bounds: Option<[usize; 4]> = None;
        let mut iterations = 0;
        loop {
            for &k in &take {
                let (i, j) = (k % n, k / n);
                bounds = Some(match bounds {
                    None => [i, i, j, j],
                    Some([i0, i1, j0, j1]) => [i0.min(i), i1.max(i), j0.min(j), j1.max(j)],
                });
            }
            let Some(b) = bounds else {
                // nothing touches
                return Ok(Contact {
                    grid,
                    pressure_mpa: vec![0.0; n * n],
                    displacement_mm: vec![0.0; n * n],
                    in_contact: vec![false; n * n],
                    load_n: 0.0,
                    iterations: 1,
                });
            };
            let [x0, y0, w] = window(b, n);
            let sub: Vec<f64> = (0..w * w)
                .map(|k| height_mm[(y0 + k / w) * n + x0 + k % w])
                .collect();
            let (pw, its) = if w == n {
                conjugate_gradient(&self.convolver, &sub, approach_mm, self.skin.e_star_mpa())?
            } else {
                let c = self.window_convolver(w);
                conjugate_gradient(&c, &sub, approach_mm, self.skin.e_star_mpa())?
            };
            iterations += its;
            let mut p = vec![0.0; n * n];
            for (k, &v) in pw.iter().enumerate() {
                p[(y0 + k / w) * n + x0 + k % w] = v;
            }
            let u = self.convolver.apply(&p);
            let inside = |k: usize| {
                let (i, j) = (k % n, k / n);
                (x0..x0 + w).contains(&i) && (y0..y0 + w).contains(&j)
            };
            take = (0..n * n)
                .filter(|&k| !inside(k) && height_mm[k] + u[k] - approach_mm < 0.0)
                .collect();
            if take.is_empty() {
                let area = grid.cell_mm * grid.cell_mm;
                return Ok(Contact {
                    grid,
                    load_n: p.iter().sum::<f64>() * area,
                    in_contact: p.iter().map(|&x| x > 0.0).collect(),
                    displacement_mm: u,
                    pressure_mpa: p,
                    iterations,
                });
            }
        }
    }
}

/// The square window `[x0, y0, w]` (its first column and row, its size a side) that holds the
/// cells `[i0, i1] x [j0, j1]` of an `n x n` grid with [`WINDOW_MARGIN`] cells round them, as
/// large as its FFTs' size allows ([`smooth_size`]), inside the grid.
fn window([i0, i1, j0, j1]: [usize; 4], n: usize) -> [usize; 3] {
    let span = (i1 - i0).max(j1 - j0) + 1 + 2 * WINDOW_MARGIN;
    let w = smooth_size(2 * span - 1).div_ceil(2).min(n);
    let start = |lo: usize, hi: usize| {
        let centre = (lo + hi).div_ceil(2);
        centre.saturating_sub(w / 2).min(n - w)
    };
    [start(i0, i1), start(j0, j1), w]
}

/// Polonsky and Keer's conjugate gradient on the `w x w` cells of `convolver` (the approach
/// given: no load balance): the pressure, MPa, per cell, and the iterations taken.
fn conjugate_gradient(
    convolver: &Convolver,
    height_mm: &[f64],
    approach_mm: f64,
    e_star_mpa: f64,
) -> Result<(Vec<f64>, usize), ContactError> {
    let cells = height_mm.len();
    let apply = |p: &[f64]| convolver.apply(p);
    let mut p: Vec<f64> = height_mm
        .iter()
        .map(|&h| {
            if h < approach_mm {
                1e-3 * e_star_mpa
            } else {
                0.0
            }
        })
        .collect();
    let mut t = vec![0.0; cells];
    let (mut g_old, mut delta) = (1.0, 0.0);
    let max_iter = 10 * cells;
    let mut change = f64::INFINITY;
    for iteration in 1..=max_iter {
        let u = apply(&p);
        let g: Vec<f64> = (0..cells)
            .map(|k| height_mm[k] + u[k] - approach_mm)
            .collect();
        let gg: f64 = (0..cells)
            .filter(|&k| p[k] > 0.0)
            .map(|k| g[k] * g[k])
            .sum();
        for k in 0..cells {
            t[k] = if p[k] > 0.0 {
                g[k] + delta * (gg / g_old) * t[k]
            } else {
                0.0
            };
        }
        g_old = gg.max(f64::MIN_POSITIVE);
        let r = apply(&t);
        let (num, den) = (0..cells)
            .filter(|&k| p[k] > 0.0)
            .fold((0.0, 0.0), |(a, b), k| (a + g[k] * t[k], b + r[k] * t[k]));
        let tau = if den > 0.0 { num / den } else { 0.0 };
        let before: f64 = p.iter().sum();
        let old = p.clone();
        for k in 0..cells {
            if p[k] > 0.0 {
                p[k] = (p[k] - tau * t[k]).max(0.0);
            }
        }
        // cells off the contact that the indenter now overlaps enter it
        let mut entered = false;
        for k in 0..cells {
            if old[k] == 0.0 && g[k] < 0.0 {
                p[k] = -tau * g[k];
                if p[k] <= 0.0 {
                    p[k] = 1e-6 * e_star_mpa;
                }
                entered = true;
            }
        }
        delta = if entered { 0.0 } else { 1.0 };
        let moved: f64 = p.iter().zip(&old).map(|(a, b)| (a - b).abs()).sum();
        change = if before > 0.0 { moved / before } else { 0.0 };
        if change < 1e-9 && !entered {
            return Ok((p, iteration));
        }
    }
    Err(ContactError::NoConvergence(max_iter, change))
}

/// `K_z(s, t)`, the normal displacement at depth `z` under the surface of a bonded layer of
/// thickness `h` against the surface's of a half-space, at the wavenumber `k`: `s = k z`,
/// `t = k h` (`t = inf`: a half-space), `nu` Poisson's ratio. From the same solution of
/// Navier's equations as [`layer_factor`] (its closed form checked against the symbolic
/// solution): `K_z(0, t) = K(t)`, `K_z(t, t) = 0` (the base holds), and for a half-space
/// `(2 + s - 2 nu) e^(-s) / (2 (1 - nu))`, Boussinesq's `z^2 / rho^3 + 2 (1 - nu) / rho`
/// under a point load (Johnson Eq. 3.21c) in Hankel's form.
pub fn depth_factor(s: f64, t: f64, nu: f64) -> f64 {
    let c = 4.0 * nu - 3.0;
    let den0 = -2.0 * (nu - 1.0) * c;
    if !t.is_finite() || t > 300.0 {
        return c * (2.0 + s - 2.0 * nu) * (-s).exp() / den0;
    }
    let (e2t, e4t) = ((-2.0 * t).exp(), (-4.0 * t).exp());
    let a =
        -8.0 * nu * nu - 4.0 * nu * t + 14.0 * nu + 2.0 * s * t - s - 2.0 * t * t + 4.0 * t - 6.0;
    let b =
        8.0 * nu * nu - 4.0 * nu * t - 14.0 * nu - 2.0 * s * t - s + 2.0 * t * t + 4.0 * t + 6.0;
    // numerator and denominator divided by e^(s + 4t)
    let num = c * (2.0 + s - 2.0 * nu) * (-s).exp()
        + c * (s + 2.0 * nu - 2.0) * (s - 4.0 * t).exp()
        + a * (-s - 2.0 * t).exp()
        + b * (s - 2.0 * t).exp();
    let den = den0 * (1.0 + e4t)
        + 4.0 * (nu - 1.0) * (8.0 * nu * nu - 12.0 * nu + 2.0 * t * t + 5.0) * e2t;
    num / den
}

/// The displacement into the skin, mm, at `depth_mm` under the surface below the centre of
/// every cell of `grid`, under a unit pressure (1 MPa) on one cell of the surface, by the
/// offset between them, as [`influence`]'s: `(1 / (pi E*)) int_0^inf K_z(kz, kh) J0(kr) dk`
/// ([`depth_factor`]), Boussinesq's point load in closed form plus the layer's smooth
/// correction (a Hankel integral), summed over the loaded cell by 5 x 5 Gauss points. `depth_mm` above 0
/// (at 0: [`influence`]), and for a layer below its thickness, at least a cell (checked by
/// [`displacement_at_depth`]).
pub fn influence_at_depth(grid: ContactGrid, skin: Skin, depth_mm: f64) -> Vec<f64> {
    let n = grid.n;
    let m = 2 * n - 1;
    let (nu, thickness_mm) = match skin {
        Skin::HalfSpace { .. } => (HALF_SPACE_POISSON, f64::INFINITY),
        Skin::BondedLayer {
            poisson,
            thickness_mm,
            ..
        } => (poisson, thickness_mm),
    };
    let half = grid.cell_mm / 2.0;
    let r_max = std::f64::consts::SQRT_2 * (n as f64 - 1.0) * grid.cell_mm + grid.cell_mm;
    // the layer's correction to Boussinesq's half-space, int (K_z - K_z,half-space) J0(kr) dk
    let table = thickness_mm.is_finite().then(|| {
        HankelTable::new(
            |k| {
                let s = k * depth_mm;
                depth_factor(s, k * thickness_mm, nu) - depth_factor(s, f64::INFINITY, nu)
            },
            thickness_mm,
            (grid.cell_mm / 8.0).min(thickness_mm / 32.0),
            r_max,
        )
    });
    let correction = |r: f64| table.as_ref().map_or(0.0, |t| t.at(r));
    // Boussinesq's point load at depth z, times pi E*: z^2 / (2 (1 - nu) rho^3) + 1 / rho
    // (Johnson Eq. 3.21c with 1 / (4 pi G) = 1 / (2 pi E* (1 - nu)))
    let z2 = depth_mm * depth_mm;
    let boussinesq = |r: f64| -> f64 {
        let rho = (r * r + z2).sqrt();
        z2 / (2.0 * (1.0 - nu) * rho * rho * rho) + 1.0 / rho
    };
    // 5-point Gauss-Legendre on [-1, 1]
    let gauss = [
        (-0.906_179_845_938_664, 0.236_926_885_056_189),
        (-0.538_469_310_105_683, 0.478_628_670_499_366),
        (0.0, 0.568_888_888_888_889),
        (0.538_469_310_105_683, 0.478_628_670_499_366),
        (0.906_179_845_938_664, 0.236_926_885_056_189),
    ];
    let scale = half * half / (std::f64::consts::PI * skin.e_star_mpa());
    let mut kernel = vec![0.0; m * m];
    for dj in 0..m {
        for di in 0..m {
            let (x, y) = (
                (di as f64 - (n as f64 - 1.0)) * grid.cell_mm,
                (dj as f64 - (n as f64 - 1.0)) * grid.cell_mm,
            );
            let mut sum = 0.0;
            for &(gy, wy) in &gauss {
                for &(gx, wx) in &gauss {
                    let r = (x - gx * half).hypot(y - gy * half);
                    sum += wx * wy * (boussinesq(r) + correction(r));
                }
            }
            kernel[dj * m + di] = scale * sum;
        }
    }
    kernel
}

/// Poisson's ratio of a half-space's interior ([`Skin::HalfSpace`] gives `E*` only): 0.5, a
/// silicone's (incompressible; its surface displacement does not depend on it).
pub const HALF_SPACE_POISSON: f64 = 0.5;

/// The normal displacement into the skin, mm, at `depth_mm` under the surface below each
/// cell's centre (row-major, as [`Contact`]) under the contact's pressure: the face under a
/// coat the camera sees (9DTact's black layer: 0.3 mm). At depth 0, the surface's.
///
/// # Errors
/// [`ContactError::Value`] for a depth that is negative, not finite, below a cell (above 0),
/// or not inside a layer.
pub fn displacement_at_depth(
    contact: &Contact,
    skin: Skin,
    depth_mm: f64,
) -> Result<Vec<f64>, ContactError> {
    if depth_mm == 0.0 {
        return Ok(contact.displacement_mm.clone());
    }
    let inside = match skin {
        Skin::HalfSpace { .. } => true,
        Skin::BondedLayer { thickness_mm, .. } => depth_mm < thickness_mm,
    };
    if !(depth_mm.is_finite() && depth_mm >= contact.grid.cell_mm && inside) {
        return Err(ContactError::Value {
            name: "depth_mm",
            value: depth_mm,
            rule: "must be 0 or at least a cell, and inside the layer",
        });
    }
    let kernel = influence_at_depth(contact.grid, skin, depth_mm);
    Ok(Convolver::new(contact.grid.n, &kernel).apply(&contact.pressure_mpa))
}

/// The least `2^a 3^b 5^c` at least `m`.
fn smooth_size(m: usize) -> usize {
    (m.max(1)..)
        .find(|&k| {
            let mut r = k;
            for p in [2, 3, 5] {
                while r % p == 0 {
                    r /= p;
                }
            }
            r == 1
        })
        .unwrap_or(m)
}

/// The convolution of an `n x n` grid of values with a kernel given at every offset
/// (`(2n - 1)^2`, as [`influence`]'s), by FFTs of at least `2n - 1` a side (circular, padded
/// so that no offset wraps; a size of small factors), with the scalar planner: the same bits
/// on every CPU.
pub struct Convolver {
    n: usize,
    /// The FFTs' size a side: the least 2^a 3^b 5^c at least `2n - 1` (fast FFTs; no offset
    /// wraps).
    big: usize,
    kernel_hat: Vec<Complex<f64>>,
    forward: std::sync::Arc<dyn rustfft::Fft<f64>>,
    inverse: std::sync::Arc<dyn rustfft::Fft<f64>>,
}

impl Convolver {
    /// The convolver of `kernel` (`(2n - 1)^2` values, offset `(di - (n - 1), dj - (n - 1))`
    /// at `dj * (2n - 1) + di`).
    pub fn new(n: usize, kernel: &[f64]) -> Convolver {
        let m = 2 * n - 1;
        let big = smooth_size(m);
        let mut planner = rustfft::FftPlannerScalar::new();
        let forward = planner.plan_fft_forward(big);
        let inverse = planner.plan_fft_inverse(big);
        let mut buf = vec![Complex::new(0.0, 0.0); big * big];
        for dj in 0..m {
            for di in 0..m {
                let (x, y) = ((di + big + 1 - n) % big, (dj + big + 1 - n) % big);
                buf[y * big + x] = Complex::new(kernel[dj * m + di], 0.0);
            }
        }
        let mut c = Convolver {
            n,
            big,
            kernel_hat: Vec::new(),
            forward,
            inverse,
        };
        c.fft2(&mut buf, false);
        c.kernel_hat = buf;
        c
    }

    /// The 2D FFT of `buf` (`2n x 2n`, row-major) in place: rows, then columns.
    fn fft2(&self, buf: &mut [Complex<f64>], inverse: bool) {
        let big = self.big;
        let fft = if inverse {
            &self.inverse
        } else {
            &self.forward
        };
        fft.process(buf);
        let mut t = vec![Complex::new(0.0, 0.0); big * big];
        for y in 0..big {
            for x in 0..big {
                t[x * big + y] = buf[y * big + x];
            }
        }
        fft.process(&mut t);
        for y in 0..big {
            for x in 0..big {
                buf[y * big + x] = t[x * big + y];
            }
        }
    }

    /// `u[i] = sum_j values[j] kernel[i - j]` over the `n x n` grid (row-major).
    pub fn apply(&self, values: &[f64]) -> Vec<f64> {
        let (n, big) = (self.n, self.big);
        let mut buf = vec![Complex::new(0.0, 0.0); big * big];
        for j in 0..n {
            for i in 0..n {
                buf[j * big + i] = Complex::new(values[j * n + i], 0.0);
            }
        }
        self.fft2(&mut buf, false);
        for (b, k) in buf.iter_mut().zip(&self.kernel_hat) {
            *b *= k;
        }
        self.fft2(&mut buf, true);
        let scale = 1.0 / (big * big) as f64;
        let mut u = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                u[j * n + i] = buf[j * big + i].re * scale;
            }
        }
        u
    }
}

/// The displacement into the skin, mm, at the centre of every cell of `grid` under a unit
/// pressure (1 MPa) on one cell, by the offset between them: `(2n - 1)^2` values, row-major,
/// offset `(di - (n - 1), dj - (n - 1))` cells at `dj * (2n - 1) + di`. The skin's values
/// are taken as checked ([`solve_skin_contact`] checks them).
pub fn influence(grid: ContactGrid, skin: Skin) -> Vec<f64> {
    let n = grid.n;
    let e_star_mpa = skin.e_star_mpa();
    // the influence of a cell's unit pressure at every offset, (2n - 1)^2
    let m = 2 * n - 1;
    let half = grid.cell_mm / 2.0;
    let scale = 1.0 / (std::f64::consts::PI * e_star_mpa);
    let mut kernel = vec![0.0; m * m];
    for dj in 0..m {
        for di in 0..m {
            let (x, y) = (
                (di as f64 - (n as f64 - 1.0)) * grid.cell_mm,
                (dj as f64 - (n as f64 - 1.0)) * grid.cell_mm,
            );
            kernel[dj * m + di] = scale * love(x, y, half);
        }
    }
    if let Skin::BondedLayer {
        poisson,
        thickness_mm,
        ..
    } = skin
    {
        // the layer's smooth correction, summed over the source cell by 3 x 3 Gauss points
        let r_max = std::f64::consts::SQRT_2 * (n as f64 - 1.0) * grid.cell_mm + grid.cell_mm;
        let dr = (grid.cell_mm / 8.0).min(thickness_mm / 32.0);
        // int (K(kh) - 1) J0(kr) dk: the layer's correction to a half-space's point load
        let table = HankelTable::new(
            |k| layer_factor_less_one(k * thickness_mm, poisson),
            thickness_mm,
            dr,
            r_max,
        );
        let at = |r: f64| table.at(r);
        let node = (0.6f64).sqrt() * half;
        let gauss = [(-node, 5.0 / 9.0), (0.0, 8.0 / 9.0), (node, 5.0 / 9.0)];
        for dj in 0..m {
            for di in 0..m {
                let (x, y) = (
                    (di as f64 - (n as f64 - 1.0)) * grid.cell_mm,
                    (dj as f64 - (n as f64 - 1.0)) * grid.cell_mm,
                );
                let mut sum = 0.0;
                for &(gy, wy) in &gauss {
                    for &(gx, wx) in &gauss {
                        sum += wx * wy * at((x - gx).hypot(y - gy));
                    }
                }
                kernel[dj * m + di] += scale * sum * half * half;
            }
        }
    }
    kernel
}

/// The heights of a sphere of `radius_mm` centred over `(cx, cy)` mm above its lowest point
/// at each cell's centre (outside its silhouette: its equator's height plus the distance
/// beyond it, so that it never touches there).
pub fn sphere_heights(grid: ContactGrid, radius_mm: f64, cx: f64, cy: f64) -> Vec<f64> {
    let n = grid.n;
    let mut h = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = grid.centre_mm(i, j);
            let r = (x - cx).hypot(y - cy);
            h.push(if r < radius_mm {
                radius_mm - (radius_mm * radius_mm - r * r).sqrt()
            } else {
                radius_mm + (r - radius_mm)
            });
        }
    }
    h
}

/// The heights above their lowest point, at each cell's centre, of a board's bumps: each a
/// cylinder of `radius_mm` capped by a hemisphere, its axis at `(x, y)` of `bumps_mm` (the
/// grid's frame: cell `(i, j)` at [`ContactGrid::centre_mm`] plus `offset_mm`), standing
/// `height_mm` on the board's floor (beyond every bump's radius the floor, `height_mm` above
/// the tips).
pub fn bump_heights(
    grid: ContactGrid,
    offset_mm: [f64; 2],
    bumps_mm: &[[f64; 2]],
    radius_mm: f64,
    height_mm: f64,
) -> Vec<f64> {
    let n = grid.n;
    let mut h = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = grid.centre_mm(i, j);
            let (x, y) = (x + offset_mm[0], y + offset_mm[1]);
            let mut best = height_mm;
            for b in bumps_mm {
                let r = (x - b[0]).hypot(y - b[1]);
                if r < radius_mm {
                    best = best.min(radius_mm - (radius_mm * radius_mm - r * r).sqrt());
                }
            }
            h.push(best);
        }
    }
    h
}
