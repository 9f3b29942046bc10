//! The seed report's four experiments: our scenes for them (`scenes/seed/`, embedded in the binary
//! so that `englobe experiment seed` runs from anywhere) and the report's own figures, from
//! Deneux and Joniaux (2009), "Pré-détermination des objets impactés par un rayon (accélération
//! du rendu)", Université de Liège, section 6. The report counts calls to the exact intersection
//! function (`getFirstIntersection`) over all the rays of one image, before and after its BVH.

/// What the report measured for one test.
#[derive(Clone, Copy, Debug)]
pub enum ReportFigures {
    /// Exact intersection tests without and with the report's BVH, and the reduction it states.
    Counts {
        /// Without a structure.
        before: f64,
        /// With the report's BVH.
        after: f64,
        /// The reduction as the report states it, in percent (the report truncates).
        stated_percent: f64,
    },
    /// No counts, only what the report says happened.
    Words {
        /// Without a structure.
        before: &'static str,
        /// With the report's BVH.
        after: &'static str,
    },
}

/// One of the report's tests and our scene for it.
#[derive(Clone, Copy, Debug)]
pub struct SeedTest {
    /// The report's test number, 1 to 4.
    pub number: u32,
    /// What the scene holds, in a few words.
    pub title: &'static str,
    /// The scene file's path in the repository.
    pub file: &'static str,
    /// The scene file's text.
    pub text: &'static str,
    /// The report's figures.
    pub report: ReportFigures,
}

/// The four tests, in the report's order.
pub const SEED_TESTS: [SeedTest; 4] = [
    SeedTest {
        number: 1,
        title: "7 spheres filling most of the image",
        file: "scenes/seed/test1.toml",
        text: include_str!("../../../scenes/seed/test1.toml"),
        report: ReportFigures::Counts { before: 2.51978e7, after: 1.61632e7, stated_percent: 35.8 },
    },
    SeedTest {
        number: 2,
        title: "the same spheres at 1/10 of their radius",
        file: "scenes/seed/test2.toml",
        text: include_str!("../../../scenes/seed/test2.toml"),
        report: ReportFigures::Counts { before: 1.83346e6, after: 422_762.0, stated_percent: 76.9 },
    },
    SeedTest {
        number: 3,
        title: "100 small spheres in 2 rows of 50",
        file: "scenes/seed/test3.toml",
        text: include_str!("../../../scenes/seed/test3.toml"),
        report: ReportFigures::Counts { before: 3.61592e7, after: 481_126.0, stated_percent: 98.6 },
    },
    SeedTest {
        number: 4,
        title: "test 1 plus 8000 spheres out of view",
        file: "scenes/seed/test4.toml",
        text: include_str!("../../../scenes/seed/test4.toml"),
        report: ReportFigures::Words { before: "< 2 % done after minutes", after: "done in seconds" },
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_parses_at_the_report_size() {
        for t in SEED_TESTS {
            let scene = englobe_scene::parse_scene(t.text, t.file.as_ref()).unwrap();
            assert_eq!((scene.image.width, scene.image.height, scene.image.samples), (512, 512, 1), "{}", t.file);
            assert!(
                scene.objects.iter().all(|o| matches!(o.object, englobe::Object::Shape(englobe::Shape::Sphere(_))))
            );
        }
    }

    #[test]
    fn the_scenes_have_the_report_s_object_counts() {
        let count = |i: usize| englobe_scene::parse_scene(SEED_TESTS[i].text, "t".as_ref()).unwrap().objects.len();
        assert_eq!([count(0), count(1), count(2), count(3)], [7, 7, 100, 8007]);
    }

    fn spheres(i: usize) -> (englobe_scene::Scene, Vec<englobe::Sphere>) {
        let scene = englobe_scene::parse_scene(SEED_TESTS[i].text, "t".as_ref()).unwrap();
        let spheres = scene
            .objects
            .iter()
            .map(|o| match o.object {
                englobe::Object::Shape(englobe::Shape::Sphere(s)) => s,
                _ => unreachable!("only spheres"),
            })
            .collect();
        (scene, spheres)
    }

    #[test]
    fn tests_2_and_4_are_built_on_test_1() {
        let (one, s1) = spheres(0);
        let (two, s2) = spheres(1);
        let (four, s4) = spheres(3);
        for (a, b) in s1.iter().zip(&s2) {
            assert_eq!(a.center, b.center);
            assert!((a.radius / 10.0 - b.radius).abs() < 1e-6);
        }
        assert_eq!(&s4[..7], &s1[..]);
        for scene in [&two, &four] {
            assert_eq!((scene.camera, &scene.lights, &scene.materials), (one.camera, &one.lights, &one.materials));
        }
    }

    #[test]
    fn test_4_s_extra_spheres_are_all_behind_the_camera() {
        let (scene, s4) = spheres(3);
        let forward = (scene.camera.look_at - scene.camera.position).normalize();
        for s in &s4[7..] {
            assert!((s.center - scene.camera.position).dot(forward) + s.radius < 0.0, "{s:?}");
        }
    }

    #[test]
    fn the_stated_reductions_truncate_the_counts() {
        for t in SEED_TESTS {
            if let ReportFigures::Counts { before, after, stated_percent } = t.report {
                let exact = 100.0 * (1.0 - after / before);
                assert!(exact >= stated_percent && exact < stated_percent + 0.1, "test {}: {exact}", t.number);
            }
        }
    }
}
