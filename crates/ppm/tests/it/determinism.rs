//! Same seed ⇒ bit-identical image, whatever the number of threads.

use ppm::{Method, Renderer};

use crate::support::{PHOTON_METHODS, cornell, params};

fn render_with_threads(
    threads: usize,
    method: Method,
    light_tracing: bool,
) -> (Vec<[f32; 3]>, Vec<u8>) {
    let scene = cornell("CornellBox-Sphere.obj", 24, 24);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut p = params(method, 6_000);
        p.film.samples_per_pixel = 2;
        p.connections.light_tracing = light_tracing;
        let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
        for _ in 0..3 {
            renderer.iterate();
        }
        (renderer.image(), renderer.save_state("determinism"))
    })
}

#[test]
fn images_are_bit_identical_for_1_2_and_8_threads() {
    let light_tracing = Method::ALL
        .into_iter()
        .map(|m| (m, false))
        .chain(PHOTON_METHODS.into_iter().map(|m| (m, true)));
    for (method, light) in light_tracing {
        let method_name = format!("{method}{}", if light { " + light tracing" } else { "" });
        let (one, state_one) = render_with_threads(1, method, light);
        for threads in [2, 8] {
            let (many, state_many) = render_with_threads(threads, method, light);
            let same = one
                .iter()
                .zip(&many)
                .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
            assert!(
                same,
                "{method_name}: image differs between 1 and {threads} threads"
            );
            assert!(
                state_one == state_many,
                "{method_name}: state differs between 1 and {threads} threads"
            );
        }
    }
}

#[test]
fn different_seeds_give_different_images() {
    let scene = cornell("CornellBox-Original.obj", 16, 16);
    let mut a = params(Method::Ppm, 4_000);
    let mut b = a;
    a.seed = 1;
    b.seed = 2;
    let image_a = crate::support::render(&scene, a, 2);
    let image_b = crate::support::render(&scene, b, 2);
    assert!(image_a != image_b);
}

/// A renderer owns its scene: it can be kept without the scene's binding, sent to another
/// thread, rendered there and sent back, and renders there what it renders here, for every
/// method.
#[test]
fn a_renderer_owns_its_scene_and_moves_between_threads() {
    fn owned<T: Send + 'static>(value: T) -> T {
        value
    }
    for method in Method::ALL {
        let here = {
            let scene = cornell("CornellBox-Sphere.obj", 16, 16);
            let mut renderer = Renderer::new(scene, params(method, 3_000)).unwrap();
            renderer.iterate();
            renderer.image()
        };
        let renderer = owned(
            Renderer::new(
                cornell("CornellBox-Sphere.obj", 16, 16),
                params(method, 3_000),
            )
            .unwrap(),
        );
        let (renderer, there) = std::thread::spawn(move || {
            let mut renderer = renderer;
            renderer.iterate();
            let image = renderer.image();
            (renderer, image)
        })
        .join()
        .unwrap();
        let bits = |image: &[[f32; 3]]| {
            image
                .iter()
                .map(|p| p.map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&here), bits(&there), "{method}");
        assert_eq!(renderer.passes(), 1);
        assert_eq!(renderer.scene().description().film.width, 16);
    }
}
