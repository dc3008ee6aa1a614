use super::*;

/// A box of smoke (density and temperature 1) near the floor.
fn smoke_source() -> Source {
    Source { min: [0.3, 0.0, 0.3], max: [0.6, 0.2, 0.6], density: 1.0, temperature: 1.0, velocity: None }
}

/// Advection-reflection projects twice: the step still ends divergence-free to the solver's
/// tolerance, with smoke carried by the midpoint field, 2D and 3D, on 1 and 2 threads alike.
#[test]
fn reflection_ends_divergence_free_and_is_thread_count_independent() {
    for (dims, dim) in [([16, 12, 1], 2), ([8, 8, 8], 3)] {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let params = MacParams {
                    splitting: Splitting::Reflection,
                    pressure_tolerance: 1e-8,
                    viscosity: 0.01,
                    buoyancy_temperature: 1.0,
                    sources: vec![smoke_source()],
                    ..MacParams::default()
                };
                let (mut f, mut s) = MacFluid::new(dims, dim, 1.0 / 16.0, params).unwrap();
                f.set_velocity(&mut s, |p| [(3.0 * p[1]).sin(), (2.0 * p[0]).cos(), 0.5 * p[1]]);
                let before = f.max_divergence(&s);
                let mut worst: f64 = 0.0;
                for _ in 0..5 {
                    let info = f.advance(&mut s, 0.05).unwrap();
                    assert!(info.pressure.converged);
                    worst = worst.max(info.divergence / before.max(1.0));
                }
                (s, worst)
            })
        };
        let (one, worst) = run(1);
        let (two, _) = run(2);
        assert!(worst < 1e-6, "{dim}D relative divergence {worst}");
        assert!(one.density.iter().sum::<f64>() > 0.5, "smoke entered");
        assert_eq!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&two).unwrap());
    }
}

/// Finite but huge densities overflow the buoyancy force (`-alpha (rho_a + rho_b) / 2` is
/// infinite): the step fails naming the step, field, face, value and the face's value
/// before the step, and leaves the state and the warm-start pressure bitwise as they were.
#[test]
fn overflow_is_reported_and_the_step_undone() {
    for (dims, dim) in [([8, 8, 1], 2), ([6, 6, 6], 3)] {
        let params = MacParams { buoyancy_density: 10.0, ..MacParams::default() };
        let (mut fluid, mut state) = MacFluid::new(dims, dim, 0.125, params).unwrap();
        fluid.set_velocity(&mut state, |p| [(3.0 * p[1]).sin() + 1.0, (2.0 * p[0]).cos(), p[0]]);
        for _ in 0..2 {
            fluid.advance(&mut state, 0.05).unwrap();
        }
        let c = idx(dims, 3, 2, dims[2] / 2);
        state.density[c] = 1e308;
        state.density[c + dims[0]] = 1e308;
        let before = state.clone();
        let memory = serde_json::to_string(&fluid.memory()).unwrap();
        assert!(fluid.memory()["pressure"].as_array().unwrap().iter().any(|p| p.as_f64() != Some(0.0)));
        let err = fluid.advance(&mut state, 0.05).unwrap_err();
        let FluidError::NonFinite { step, field, i, j, k, value, last_finite } = err.clone() else {
            panic!("{err}")
        };
        assert_eq!(step, 2);
        assert!(!value.is_finite());
        let (old, d) = match field {
            "u" => (&before.vel[0], fluid.face_dims(0)),
            "v" => (&before.vel[1], fluid.face_dims(1)),
            "w" => (&before.vel[2], fluid.face_dims(2)),
            "density" => (&before.density, dims),
            "temperature" => (&before.temperature, dims),
            other => panic!("field {other}"),
        };
        assert!(i < d[0] && j < d[1] && k < d[2], "{err}");
        let last = old[idx(d, i, j, k)];
        assert_eq!(last_finite, Some(last));
        let msg = err.to_string();
        assert!(msg.starts_with("anim-fluid: step 2: non-finite "), "{msg}");
        assert!(msg.contains(&format!("{field} {value} at cell ({i}, {j}, {k})")), "{msg}");
        assert!(msg.contains(&format!("last finite value there {last}")), "{msg}");
        let bits = |s: &MacState| {
            s.vel
                .iter()
                .chain([&s.density, &s.temperature])
                .flatten()
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&state), bits(&before));
        assert_eq!((state.steps, state.time.to_bits()), (before.steps, before.time.to_bits()));
        assert_eq!(serde_json::to_string(&fluid.memory()).unwrap(), memory, "warm start changed");
    }
}

/// Every pressure method and advection scheme, 2D and 3D: the state and the solver's memory
/// continue a run bit for bit.
#[test]
fn state_and_memory_continue_bit_for_bit() {
    for (k, method) in PressureMethod::ALL.into_iter().enumerate() {
        for (dims, dim) in [([10, 8, 1], 2), ([6, 5, 4], 3)] {
            let params = MacParams {
                pressure: method,
                pressure_tolerance: 1e-6,
                pressure_max_iterations: 100_000,
                viscosity: 0.01,
                advection: Advection::ALL[k % 4],
                splitting: Splitting::ALL[(k / 2) % 2],
                buoyancy_temperature: 1.0,
                vorticity_confinement: 1.0,
                sources: vec![smoke_source()],
                ..MacParams::default()
            };
            let build = || {
                let (mut f, mut s) = MacFluid::new(dims, dim, 0.1, params.clone()).unwrap();
                f.set_solid(|p| (p[0] - 0.7).powi(2) + (p[1] - 0.5).powi(2) < 0.01).unwrap();
                f.set_velocity(&mut s, |p| [(3.0 * p[1]).sin(), (2.0 * p[0]).cos(), 0.5 * p[1]]);
                (f, s)
            };
            let (mut f, mut s) = build();
            for _ in 0..2 {
                f.advance(&mut s, 0.05).unwrap();
            }
            let saved = serde_json::to_string(&(&s, f.memory())).unwrap();
            for _ in 0..3 {
                f.advance(&mut s, 0.05).unwrap();
            }
            let (mut g, _) = build();
            let (mut r, memory): (MacState, serde_json::Value) = serde_json::from_str(&saved).unwrap();
            g.check_state(&r).unwrap();
            g.restore_memory(&memory).unwrap();
            for _ in 0..3 {
                g.advance(&mut r, 0.05).unwrap();
            }
            let text = |s: &MacState, f: &MacFluid| serde_json::to_string(&(s, f.memory())).unwrap();
            assert_eq!(text(&s, &f), text(&r, &g), "{method:?} {dim}D");
        }
    }
}

#[test]
fn projection_leaves_divergence_below_tolerance_with_an_obstacle() {
    for method in PressureMethod::ALL {
        let params = MacParams {
            pressure: method,
            pressure_tolerance: 1e-8,
            pressure_max_iterations: 100_000,
            ..MacParams::default()
        };
        let (mut fluid, mut state) = MacFluid::new([24, 20, 1], 2, 0.05, params).unwrap();
        fluid.set_solid(|p| (p[0] - 0.6).powi(2) + (p[1] - 0.5).powi(2) < 0.04).unwrap();
        fluid.set_velocity(&mut state, |p| [(3.0 * p[1]).sin() + 1.0, (2.0 * p[0]).cos(), 0.0]);
        let before = fluid.max_divergence(&state);
        let info = fluid.advance(&mut state, 0.01).unwrap();
        assert!(info.pressure.converged, "{method:?}");
        assert!(
            info.divergence < 1e-6 * before.max(1.0),
            "{method:?}: {} (before {before})",
            info.divergence
        );
    }
}

/// A region source raises the density of its fluid cells (never lowers it), sets their
/// temperature and the velocity of its free faces; solid cells and wall and obstacle faces keep
/// their values. A bad mask or value is refused.
#[test]
fn a_region_source_acts_on_its_fluid_cells_and_free_faces() {
    let (dims, h) = ([6, 5, 4], 0.25);
    let (mut fluid, mut state) = MacFluid::new(dims, 3, h, MacParams::default()).unwrap();
    // Solid: the cells with i = 3.
    let solid: Vec<bool> = (0..120).map(|c| c % 6 == 3).collect();
    fluid.set_solid_cells(&solid).unwrap();
    assert_eq!(fluid.solid(), &solid[..]);
    // The region: every cell with j <= 1 and every face with j <= 1.
    let cells: Vec<bool> = (0..120).map(|c| (c / 6) % 5 <= 1).collect();
    let faces: [Vec<bool>; 3] = std::array::from_fn(|a| {
        let d = fluid.face_dims(a);
        (0..d.iter().product()).map(|f| (f / d[0]) % d[1] <= 1).collect()
    });
    let v = [0.25, -0.5, 0.75];
    let source = RegionSource { cells, faces, density: 0.6, temperature: 2.0, velocity: Some(v) };
    let mut bad = source.clone();
    bad.cells.pop();
    assert!(matches!(fluid.add_region_source(bad), Err(FluidError::BadLength { .. })));
    let mut bad = source.clone();
    bad.velocity = Some([0.0, f64::NAN, 0.0]);
    assert!(matches!(fluid.add_region_source(bad), Err(FluidError::BadParameter { .. })));
    fluid.add_region_source(source.clone()).unwrap();
    state.density.fill(0.3);
    state.density[6 * 5 * 2 + 6] = 0.9; // cell (0, 1, 2): above the source's density
    fluid.apply_sources(&mut state);
    for c in 0..120 {
        let (i, j) = (c % 6, (c / 6) % 5);
        let expected = match (j <= 1, i == 3) {
            (true, false) if c == 66 => (0.9, 2.0),
            (true, false) => (0.6, 2.0),
            _ => (0.3, 0.0),
        };
        assert_eq!((state.density[c], state.temperature[c]), expected, "cell {c}");
    }
    for a in 0..3 {
        let d = fluid.face_dims(a);
        for f in 0..d.iter().product::<usize>() {
            let (i, j, k) = (f % d[0], (f / d[0]) % d[1], f / (d[0] * d[1]));
            let n = [i, j, k];
            let wall = n[a] == 0 || n[a] == dims[a];
            let obstacle = !wall && {
                let stride = [1, 6, 30][a];
                let hi = idx(dims, i, j, k);
                solid[hi] || solid[hi - stride]
            };
            let expected = if j <= 1 && !wall && !obstacle { v[a] } else { 0.0 };
            assert_eq!(state.vel[a][f], expected, "component {a} face ({i}, {j}, {k})");
        }
    }
}
