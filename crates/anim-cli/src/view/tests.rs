//! The view's pictures: obstacles, framing, y up, 2-D scenes, pins, colours.

use super::*;

/// Pixels other than the white background.
fn painted(canvas: &Canvas) -> Vec<(u32, u32)> {
    let w = canvas.width();
    (0..canvas.pixels().len() as u32)
        .map(|i| (i % w, i / w))
        .filter(|&(x, y)| canvas.pixel(x, y) != [255, 255, 255])
        .collect()
}

/// A box and a capsule through the middle of the view cover the centre pixel with a grey
/// of the obstacle colour's hue; a tank around the view is drawn as edges and leaves its
/// middle empty; a ground or attractor is not an obstacle.
#[test]
fn obstacles_are_drawn_solid_and_tanks_as_edges() {
    let camera = Camera::framing([-1.0; 3], [1.0; 3], VIEW_DIRECTION, UP);
    let grey = |p: [u8; 3]| p != [255, 255, 255] && p[0].abs_diff(p[1]) <= 12 && p[1].abs_diff(p[2]) <= 12;
    for prop in [
        Prop::Cuboid { lo: [-0.3; 3], hi: [0.3; 3] },
        Prop::Capsule { a: [-0.8, 0.0, 0.0], b: [0.8, 0.0, 0.0], radius: 0.1 },
    ] {
        let mut canvas = Canvas::new(120, 120, [255, 255, 255]);
        draw_obstacle(&mut canvas, &camera, &prop).unwrap();
        assert!(grey(canvas.pixel(60, 60)), "{prop:?}: {:?}", canvas.pixel(60, 60));
    }
    let mut canvas = Canvas::new(120, 120, [255, 255, 255]);
    draw_obstacle(&mut canvas, &camera, &Prop::Tank { lo: [-1.0; 3], hi: [1.0; 3] }).unwrap();
    assert_eq!(canvas.pixel(60, 60), [255, 255, 255]);
    assert!(painted(&canvas).len() > 200, "{} pixels of edges", painted(&canvas).len());
    let mut context = Context::default();
    context.point_dim = 3;
    context.props = vec![
        Prop::Ground { height: 0.0 },
        Prop::Cuboid { lo: [0.0; 3], hi: [1.0; 3] },
        Prop::Tank { lo: [0.0; 3], hi: [2.0; 3] },
    ];
    let geometry = Geometry::from_context(&context);
    let Geometry::Particles { ground, obstacles, .. } = geometry else { panic!("particles") };
    assert_eq!((ground, obstacles.len()), (Some(0.0), 2));
}

/// The painted pixels' bounding box, `(x0, y0, x1, y1)`, `y` down; something must be.
fn extent(canvas: &Canvas) -> (u32, u32, u32, u32) {
    assert!(!painted(canvas).is_empty(), "nothing drawn");
    painted(canvas)
        .iter()
        .fold((u32::MAX, u32::MAX, 0, 0), |(a, b, c, d), &(x, y)| (a.min(x), b.min(y), c.max(x), d.max(y)))
}

/// A particle context whose region is the unit cube about the origin.
fn particles(planar: bool) -> View {
    let mut context = Context::default();
    context.point_dim = 3;
    context.point_radius = 0.05;
    context.planar = planar;
    context.bounds = Some(([-1.0; 3], [1.0; 3]));
    View::new(Geometry::from_context(&context))
}

/// The camera frames every point the run reached, not only the context's region: a body
/// that leaves that region (the snowball flying off) stays in the picture, drawn inside the
/// canvas; with the camera of the region alone it would be off the picture.
#[test]
fn the_camera_frames_the_whole_run() {
    let far = Snapshot { x: vec![6.0, 0.0, 0.0], ..Snapshot::default() };
    let mut view = particles(false);
    let hint = view.camera(4.0 / 3.0);
    let mut canvas = Canvas::new(160, 120, [255, 255, 255]);
    view.draw(&mut canvas, &hint, &far, &[]).unwrap();
    assert!(painted(&canvas).is_empty(), "the far point is outside the region's picture");
    view.see(&Snapshot { x: vec![0.0; 3], ..Snapshot::default() });
    view.see(&far);
    view.see(&Snapshot { x: vec![f64::NAN, 1e300, 0.0], ..Snapshot::default() });
    let camera = view.camera(4.0 / 3.0);
    view.draw(&mut canvas, &camera, &far, &[]).unwrap();
    assert!(painted(&canvas).len() > 4, "the far point is not drawn");
    let (x0, y0, x1, y1) = extent(&canvas);
    assert!(x0 > 0 && y0 > 0 && x1 < 159 && y1 < 119, "{:?}", extent(&canvas));
}

/// A 3-D scene stands y up in the picture: a point above another (greater y) is drawn
/// higher; the ground `y = 0` is drawn below the points above it.
#[test]
fn a_3d_scene_is_drawn_y_up() {
    let mut context = Context::default();
    context.point_dim = 3;
    context.point_radius = 0.1;
    context.bounds = Some(([-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]));
    let mut view = View::new(Geometry::from_context(&context));
    let camera = view.camera(1.0);
    let row = |view: &mut View, y: f64| {
        let mut canvas = Canvas::new(100, 100, [255, 255, 255]);
        view.draw(&mut canvas, &camera, &Snapshot { x: vec![0.0, y, 0.0], ..Snapshot::default() }, &[])
            .unwrap();
        let (_, y0, _, y1) = extent(&canvas);
        (y0 + y1) / 2
    };
    let (low, high) = (row(&mut view, 0.5), row(&mut view, 1.5));
    assert!(high + 10 < low, "y = 1.5 drawn at row {high}, y = 0.5 at row {low}");
    context.props = vec![Prop::Ground { height: 0.0 }];
    let mut view = View::new(Geometry::from_context(&context));
    let camera = view.camera(1.0);
    let mut canvas = Canvas::new(100, 100, [255, 255, 255]);
    view.draw(&mut canvas, &camera, &Snapshot::default(), &[]).unwrap();
    let (_, top, _, bottom) = extent(&canvas);
    assert!(bottom > low && top > high, "the ground spans rows {top} to {bottom}");
}

/// A 2-D scene is drawn face on: x to the right, y up, orthographic (a point's place does
/// not depend on its depth, which a 2-D scene does not have anyway).
#[test]
fn a_2d_scene_is_drawn_in_its_plane() {
    let mut view = particles(true);
    let camera = view.camera(1.0);
    let at = |view: &mut View, p: [f64; 3]| {
        let mut canvas = Canvas::new(100, 100, [255, 255, 255]);
        view.draw(&mut canvas, &camera, &Snapshot { x: p.to_vec(), ..Snapshot::default() }, &[]).unwrap();
        let (x0, y0, x1, y1) = extent(&canvas);
        ((x0 + x1) / 2, (y0 + y1) / 2)
    };
    let (x, y) = at(&mut view, [0.0; 3]);
    assert!(x.abs_diff(50) <= 1 && y.abs_diff(50) <= 1, "{x} {y}");
    let (x, y) = at(&mut view, [0.8, 0.8, 0.0]);
    assert!(x > 85 && y < 15, "{x} {y}");
    assert_eq!(at(&mut view, [0.8, 0.8, 0.7]), (x, y), "orthographic");
}

/// A mesh obstacle of the context (a tetrahedron around the view's centre) is drawn solid
/// in the obstacle grey where it covers the picture, and nowhere else.
#[test]
fn mesh_obstacles_are_drawn_solid() {
    let mut context = Context::default();
    context.point_dim = 3;
    context.bounds = Some(([-1.0; 3], [1.0; 3]));
    let s = 0.5;
    context.mesh_props = vec![MeshProp {
        positions: vec![[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]],
        triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    }];
    let camera = Camera::framing([-1.0; 3], [1.0; 3], VIEW_DIRECTION, UP);
    let mut view = View::new(Geometry::from_context(&context));
    let mut canvas = Canvas::new(120, 120, [255, 255, 255]);
    view.draw(&mut canvas, &camera, &Snapshot::default(), &[]).unwrap();
    let centre = canvas.pixel(60, 60);
    assert!(centre != [255, 255, 255] && centre[0].abs_diff(centre[2]) <= 12, "{centre:?}");
    // The tetrahedron's bounding box (about a third of the view) bounds what is painted.
    let painted = painted(&canvas);
    assert!(
        painted.len() > 300 && painted.iter().all(|&(x, y)| (20..100).contains(&x) && (20..100).contains(&y)),
        "{}",
        painted.len()
    );
}

/// A pinned point is marked by a dark bead over the body; an unpinned one is not.
#[test]
fn pins_are_drawn_as_dark_beads() {
    let mut context = Context::default();
    context.point_dim = 3;
    context.point_radius = 0.05;
    context.bounds = Some(([-1.0; 3], [1.0; 3]));
    context.pins = vec![1];
    let mut view = View::new(Geometry::from_context(&context));
    let camera = Camera::xy_plane([-1.0, -1.0], [1.0, 1.0], 1.0);
    let mut canvas = Canvas::new(100, 100, [255, 255, 255]);
    let s = Snapshot { x: vec![-0.5, 0.0, 0.0, 0.5, 0.0, 0.0], ..Snapshot::default() };
    view.draw(&mut canvas, &camera, &s, &[]).unwrap();
    let dark = |p: [u8; 3]| p.iter().all(|&c| c < 60);
    assert!(dark(canvas.pixel(75, 50)), "the pin: {:?}", canvas.pixel(75, 50));
    assert!(!dark(canvas.pixel(25, 50)), "the free point: {:?}", canvas.pixel(25, 50));
}

/// Points painted by a field take its colours: the ends of viridis over the range for a
/// scalar, the categorical palette for material ids.
#[test]
fn painted_points_take_the_fields_colours() {
    let mut view = particles(true);
    let camera = Camera::xy_plane([-1.0, -1.0], [1.0, 1.0], 1.0);
    let s = Snapshot { x: vec![-0.5, 0.0, 0.0, 0.5, 0.0, 0.0], ..Snapshot::default() };
    let near = |a: [u8; 3], b: [u8; 3]| {
        // Shading darkens but keeps the hue: compare the channels' proportions.
        let (sa, sb) =
            (a.iter().map(|&c| f64::from(c)).sum::<f64>(), b.iter().map(|&c| f64::from(c)).sum::<f64>());
        (0..3).all(|k| (f64::from(a[k]) / sa - f64::from(b[k]) / sb).abs() < 0.08)
    };
    view.paint(Paint::Field(SPEED.into()), (0.0, 2.0));
    let mut canvas = Canvas::new(100, 100, [255, 255, 255]);
    view.draw(&mut canvas, &camera, &s, &[0.0, 2.0]).unwrap();
    let (low, high) = (canvas.pixel(25, 50), canvas.pixel(75, 50));
    assert!(near(low, anim_io::preview::colormap::viridis(0.0)), "{low:?}");
    assert!(near(high, anim_io::preview::colormap::viridis(1.0)), "{high:?}");
    view.paint(Paint::Field(MATERIAL.into()), (0.0, 1.0));
    canvas.clear();
    view.draw(&mut canvas, &camera, &s, &[0.0, 1.0]).unwrap();
    let palette = anim_io::preview::colormap::CATEGORIES;
    assert!(near(canvas.pixel(25, 50), palette[0]), "{:?}", canvas.pixel(25, 50));
    assert!(near(canvas.pixel(75, 50), palette[1]), "{:?}", canvas.pixel(75, 50));
}

/// A grid scene draws its colliders over the field: the smoke plume's sphere in the middle of
/// a 3-D grid covers the centre of the picture in grey; the field shows elsewhere.
#[test]
fn a_grids_obstacles_are_drawn_over_its_field() {
    let mut context = Context::default();
    context.image = Some(anim_core::scene::ImageGrid {
        dims: [8, 8, 8],
        dim: 3,
        origin: [0.0; 3],
        spacing: 0.125,
        shown: "density",
        range: (0.0, 1.0),
    });
    context.props = vec![Prop::Sphere { center: [0.5, 0.5, 0.5], radius: 0.2 }];
    let mut view = View::new(Geometry::from_context(&context));
    let camera = view.camera(1.0);
    let mut canvas = Canvas::new(80, 80, [255, 255, 255]);
    view.draw(&mut canvas, &camera, &Snapshot { x: vec![0.5; 512], ..Snapshot::default() }, &[]).unwrap();
    let centre = canvas.pixel(40, 40);
    assert!(centre[0].abs_diff(centre[2]) <= 12 && centre[0] > 100, "the sphere: {centre:?}");
    assert_eq!(canvas.pixel(4, 4), anim_io::preview::colormap::viridis(0.5), "the field");
}

/// A prop that moves with the scene (the flag's pole) is drawn where the frame puts it, and the
/// camera frames it: a sphere prop of one frame covers its place in grey, and is gone from the
/// next frame that does not hold it.
#[test]
fn moving_props_are_drawn_where_each_frame_puts_them() {
    let mut view = particles(true);
    let camera = Camera::xy_plane([-1.0, -1.0], [1.0, 1.0], 1.0);
    let ball = Prop::Sphere { center: [0.5, 0.5, 0.0], radius: 0.2 };
    let with = Snapshot { x: vec![-0.5, -0.5, 0.0], props: vec![ball], ..Snapshot::default() };
    let mut canvas = Canvas::new(100, 100, [255, 255, 255]);
    view.draw(&mut canvas, &camera, &with, &[]).unwrap();
    let there = canvas.pixel(75, 25);
    assert!(there != [255, 255, 255] && there[0].abs_diff(there[2]) <= 12, "{there:?}");
    canvas.clear();
    view.draw(&mut canvas, &camera, &Snapshot { props: Vec::new(), ..with.clone() }, &[]).unwrap();
    assert_eq!(canvas.pixel(75, 25), [255, 255, 255]);
    // Seen, a far prop widens the picture.
    let far = Prop::Sphere { center: [9.0, 0.0, 0.0], radius: 0.5 };
    view.see(&Snapshot { x: vec![0.0; 3], props: vec![far], ..Snapshot::default() });
    assert!(view.region().1[0] >= 9.5, "{:?}", view.region());
}
