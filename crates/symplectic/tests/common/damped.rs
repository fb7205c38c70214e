// A model with damped force elements, shared by the integration tests (`common/mod.rs`) and
// the unit tests of `galerkin` (both `include!` it).

/// A chain of `n` unit rods pinned end to end (like `models::n_link_chain`) with a rotary
/// spring-damper between consecutive links and a point spring-damper from each link to the
/// one after next: force elements with stiffness and damping that couple bodies two apart.
pub fn damped_spring_chain(n: usize) -> mbd_model::System {
    use mbd_model::{Body, BodyRef, Force, Joint, SystemBuilder};
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let th = -std::f64::consts::FRAC_PI_2 + 0.5;
    let (s, c) = th.sin_cos();
    let mut prev = BodyRef::Ground;
    let mut prev_end = [0.0, 0.0];
    let mut links = Vec::new();
    for i in 0..n {
        let (cx, cy) = ((i as f64 + 0.5) * c, (i as f64 + 0.5) * s);
        let h = b.add_body(Body::new(format!("link{i}")).rod(1.0, 1.0).position(cx, cy, th));
        b.add_joint(Joint::revolute(format!("pin{i}"), prev, prev_end, h, [-0.5, 0.0]));
        if i >= 1 {
            b.add_force(Force::rotary_spring_damper(
                format!("rot{i}"),
                links[i - 1],
                h,
                20.0,
                0.3,
                0.0,
            ));
        }
        if i >= 2 {
            b.add_force(Force::spring_damper(
                format!("spr{i}"),
                links[i - 2],
                [0.0, 0.0],
                h,
                [0.0, 0.0],
                50.0,
                0.5,
                2.0,
            ));
        }
        links.push(h);
        prev = h.into();
        prev_end = [0.5, 0.0];
    }
    b.build().expect("damped spring chain")
}
