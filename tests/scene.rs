//! The scene planner: for every combination of cues and every input kind the
//! plan is exactly the closure of what the cues need (checked against a
//! hand-written table per cue), in a valid order, with the run counts the
//! lifetimes promise.

use shapecue::scene::planner::{Cue, Input, Lifetime, Pass, plan};
use std::collections::BTreeSet;

const INPUTS: [Input; 4] = [
    Input::Static,
    Input::Skinned,
    Input::Flipbook,
    Input::Volume,
];

/// What each cue needs, written out by hand from the issue (not derived from
/// the planner's tables): AO needs k1, k2 but not dk; suggestive contours need
/// dk; contours need only normals; creases need face normals and the edge
/// buffer; curvature colours need k1, k2.
fn expected(cue: Cue, input: Input) -> BTreeSet<Pass> {
    use Pass::*;
    let mut v: Vec<Pass> = match cue {
        Cue::Shading => vec![VertexNormals, Render],
        Cue::CurvatureColors => vec![OneRings, VertexNormals, Curvature, Render],
        Cue::AmbientOcclusion => vec![OneRings, VertexNormals, Curvature, Ao, Render],
        // rtsc's contour test reads κr: curvature, not its derivative.
        Cue::Contours => vec![OneRings, VertexNormals, Curvature, Contours, Render],
        Cue::SuggestiveContours => {
            vec![
                OneRings,
                VertexNormals,
                Curvature,
                Dcurv,
                SuggestiveContours,
                Render,
            ]
        }
        Cue::FeatureEdges => vec![EdgeBuffer, CapBuffer, FaceNormals, Edges, Caps, Render],
        // Traced on the field itself; a volume's frame still draws its
        // isosurface (shaded, or flat to hide the strokes behind it).
        Cue::CurvatureStrokes if input == Input::Volume => vec![SdfLines, Isosurface, Render],
        Cue::CurvatureStrokes => vec![SdfLines, Render],
        // Curvature line families: the pose terms read curvature and dcurv;
        // apparent ridges read curvature (no dcurv) per view; isophotes and
        // boundaries only the normals (n·l, and n·v for culling).
        Cue::Ridges | Cue::Valleys | Cue::KZero | Cue::HZero => vec![
            OneRings,
            VertexNormals,
            Curvature,
            Dcurv,
            LinesPose,
            LinesCurves,
            Render,
        ],
        Cue::ApparentRidges => vec![
            OneRings,
            VertexNormals,
            Curvature,
            LinesView,
            LinesDt1q1,
            LinesCurves,
            Render,
        ],
        Cue::PrincipalHighlights => vec![
            OneRings,
            VertexNormals,
            Curvature,
            Dcurv,
            LinesPose,
            LinesView,
            LinesCurves,
            Render,
        ],
        Cue::SuggestiveHighlights | Cue::DwkrZero => vec![
            OneRings,
            VertexNormals,
            Curvature,
            Dcurv,
            LinesCurves,
            Render,
        ],
        // The curvature's normals (its one-rings), as every family uses.
        Cue::Isophotes => vec![OneRings, VertexNormals, LinesView, LinesCurves, Render],
        Cue::Boundaries => vec![OneRings, VertexNormals, LinesCurves, Render],
        // Found over the BVH of the pose.
        Cue::IntersectionLines => vec![Bvh, Intersections, Render],
    };
    let needs_geometry = v.iter().any(|p| {
        matches!(
            p,
            VertexNormals | FaceNormals | OneRings | EdgeBuffer | CapBuffer | Bvh
        )
    });
    if needs_geometry {
        v.extend(match input {
            Input::Static => None,
            Input::Skinned => Some(Skinning),
            Input::Flipbook => Some(LoadFrame),
            Input::Volume => Some(Isosurface),
        });
    }
    v.into_iter().collect()
}

#[test]
fn every_combination_plans_exactly_the_closure() {
    for input in INPUTS {
        for mask in 0u32..(1 << Cue::ALL.len()) {
            let cues: Vec<Cue> = Cue::ALL
                .iter()
                .enumerate()
                .filter(|(i, _)| mask >> i & 1 == 1)
                .map(|(_, &c)| c)
                .collect();
            let p = plan(&cues, input);
            let want: BTreeSet<Pass> = cues.iter().flat_map(|&c| expected(c, input)).collect();
            let got: BTreeSet<Pass> = p.passes.iter().copied().collect();
            assert_eq!(got, want, "{input:?} {cues:?}");
            assert_eq!(got.len(), p.passes.len(), "no pass twice");
            // Valid order: every pass follows what it reads.
            for (i, &pass) in p.passes.iter().enumerate() {
                for need in pass.needs(input) {
                    let j = p
                        .passes
                        .iter()
                        .position(|&q| q == need)
                        .expect("need planned");
                    assert!(j < i, "{input:?} {cues:?}: {need:?} after {pass:?}");
                }
            }
        }
    }
}

#[test]
fn the_issue_s_dependency_rules() {
    let s = Input::Skinned;
    assert!(!plan(&[Cue::AmbientOcclusion], s).contains(Pass::Dcurv));
    assert!(plan(&[Cue::SuggestiveContours], s).contains(Pass::Dcurv));
    let c = plan(&[Cue::Contours], s);
    assert!(c.contains(Pass::Curvature) && !c.contains(Pass::Dcurv));
    let e = plan(&[Cue::FeatureEdges], s);
    assert!(e.contains(Pass::FaceNormals) && e.contains(Pass::EdgeBuffer));
    assert!(!e.contains(Pass::Curvature));
    let k = plan(&[Cue::CurvatureColors], s);
    assert!(k.contains(Pass::Curvature) && !k.contains(Pass::Dcurv) && !k.contains(Pass::Ao));
    assert!(plan(&[], s).passes.is_empty());
}

#[test]
fn run_counts_follow_the_lifetimes() {
    let all = Cue::ALL;
    // Skinned: pose passes once per frame, view passes per frame and camera,
    // topology once.
    let p = plan(&all, Input::Skinned);
    assert_eq!(p.runs(Pass::EdgeBuffer, 10, 4), 1);
    assert_eq!(p.runs(Pass::Skinning, 10, 4), 10);
    assert_eq!(p.runs(Pass::Curvature, 10, 4), 10);
    assert_eq!(p.runs(Pass::Render, 10, 4), 40);
    // Static mesh: curvature once over all frames and cameras.
    let p = plan(&all, Input::Static);
    assert_eq!(p.runs(Pass::Curvature, 10, 4), 1);
    assert_eq!(p.runs(Pass::Dcurv, 10, 4), 1);
    assert_eq!(p.runs(Pass::Contours, 10, 4), 40);
    // Volume: topology changes every pose.
    let p = plan(&all, Input::Volume);
    assert_eq!(Pass::OneRings.lifetime(Input::Volume), Lifetime::Pose);
    assert_eq!(p.runs(Pass::OneRings, 10, 4), 10);
    assert_eq!(p.runs(Pass::Isosurface, 10, 4), 10);
    // Passes not planned never run.
    assert_eq!(
        plan(&[Cue::Contours], Input::Static).runs(Pass::Ao, 10, 4),
        0
    );
    let text = plan(&[Cue::AmbientOcclusion], Input::Skinned).explain(3, 2);
    assert!(
        text.contains(" ao ") && text.contains("skinning") && !text.contains("dcurv"),
        "{text}"
    );
}

#[test]
fn line_family_cues_plan_only_what_they_read_with_their_lifetimes() {
    use Pass::*;
    let st = Input::Static;
    let iso = plan(&[Cue::Isophotes], st);
    assert_eq!(
        iso.passes,
        vec![OneRings, VertexNormals, LinesView, LinesCurves, Render]
    );
    let b = plan(&[Cue::Boundaries], st);
    assert_eq!(b.passes, vec![OneRings, VertexNormals, LinesCurves, Render]);
    let ar = plan(&[Cue::ApparentRidges], st);
    assert!(ar.contains(LinesDt1q1) && ar.contains(Curvature));
    assert!(!ar.contains(Dcurv) && !ar.contains(LinesPose));
    let r = plan(&[Cue::Ridges, Cue::Valleys], st);
    assert!(r.contains(Dcurv) && r.contains(LinesPose) && !r.contains(LinesView));
    // Lifetimes: pose terms once per pose, view terms and segments per view.
    for input in INPUTS {
        assert_eq!(LinesPose.lifetime(input), Lifetime::Pose);
        for p in [LinesView, LinesDt1q1, LinesCurves] {
            assert_eq!(p.lifetime(input), Lifetime::View);
        }
    }
    let all = plan(&Cue::LINE_FAMILIES, Input::Skinned);
    assert_eq!(all.runs(LinesPose, 10, 4), 10);
    assert_eq!(all.runs(LinesView, 10, 4), 40);
    assert_eq!(all.runs(LinesDt1q1, 10, 4), 40);
    assert_eq!(all.runs(LinesCurves, 10, 4), 40);
    let all = plan(&Cue::LINE_FAMILIES, st);
    assert_eq!(all.runs(LinesPose, 10, 4), 1, "a static mesh has one pose");
    // Each pass names its kernels, joined to the timing by typed id.
    let names = |p: Pass| -> Vec<&str> { p.kernels().iter().map(|k| k.kernel()).collect() };
    assert_eq!(names(LinesPose), ["lines_pose"]);
    assert_eq!(names(LinesView), ["lines_view"]);
    assert_eq!(names(LinesDt1q1), ["lines_dt1q1"]);
    assert_eq!(names(LinesCurves), ["lines_vertex", "lines_curves"]);
    // Every line cue is a family, with its scene key.
    for c in Cue::LINE_FAMILIES {
        let f = c.family().expect("a family");
        assert_eq!(c.key(), f.name().replace('-', "_"), "{c:?}");
    }
    let text = plan(&[Cue::Ridges], Input::Flipbook).explain(3, 2);
    assert!(
        text.contains("lines_pose")
            && text.contains("lines_curves")
            && !text.contains("lines_view"),
        "{text}"
    );
}

#[test]
fn the_cap_variant_decides_the_cap_passes() {
    use shapecue::scene::planner::plan_with;
    use shapecue::spec::edges::CapMode;
    for input in INPUTS {
        let adj = plan_with(&[Cue::FeatureEdges], input, CapMode::Adjacency);
        assert_eq!(adj, plan(&[Cue::FeatureEdges], input));
        assert!(adj.contains(Pass::Caps) && adj.contains(Pass::CapBuffer));
        let mh = plan_with(&[Cue::FeatureEdges], input, CapMode::Mh);
        assert!(mh.contains(Pass::Caps) && !mh.contains(Pass::CapBuffer));
        assert!(mh.contains(Pass::VertexNormals) && !adj.contains(Pass::VertexNormals));
        let none = plan_with(&[Cue::FeatureEdges], input, CapMode::None);
        assert!(!none.contains(Pass::Caps) && !none.contains(Pass::CapBuffer));
        assert!(none.contains(Pass::Edges) && none.contains(Pass::EdgeBuffer));
        // Other cues are unaffected.
        let all = plan_with(&Cue::ALL, input, CapMode::None);
        let full = plan(&Cue::ALL, input);
        let diff: Vec<Pass> = full
            .passes
            .iter()
            .copied()
            .filter(|p| !all.contains(*p))
            .collect();
        assert_eq!(diff, vec![Pass::CapBuffer, Pass::Caps]);
    }
}

#[test]
fn curvature_strokes_plan_per_input_kind() {
    use Pass::*;
    // The table for every input kind: which accept the cue, and what the
    // strokes alone plan (no mesh curvature pass on a volume).
    let table: [(Input, bool, Vec<Pass>); 4] = [
        (Input::Static, false, vec![SdfLines, Render]),
        (Input::Skinned, false, vec![SdfLines, Render]),
        (Input::Flipbook, false, vec![SdfLines, Render]),
        (Input::Volume, true, vec![Isosurface, SdfLines, Render]),
    ];
    for (input, accepted, passes) in table {
        assert_eq!(Cue::CurvatureStrokes.accepts(input), accepted, "{input:?}");
        let p = plan(&[Cue::CurvatureStrokes], input);
        assert_eq!(p.passes, passes, "{input:?}");
        for c in Cue::ALL.iter().filter(|&&c| c != Cue::CurvatureStrokes) {
            assert!(c.accepts(input), "{c:?} on {input:?}");
        }
    }
    let v = plan(&[Cue::CurvatureStrokes], Input::Volume);
    for p in [OneRings, VertexNormals, Curvature, Dcurv, Ao] {
        assert!(!v.contains(p), "{p:?} planned for strokes alone");
    }
    assert_eq!(SdfLines.lifetime(Input::Volume), Lifetime::Pose);
    assert_eq!(v.runs(SdfLines, 3, 2), 3, "once per pose, not per view");
    // Over shading: the normals of the shading, still no curvature.
    let s = plan(&[Cue::CurvatureStrokes, Cue::Shading], Input::Volume);
    assert_eq!(s.passes, vec![Isosurface, VertexNormals, SdfLines, Render]);
    // Its kernels are the sdf_lines steps, joined to the timing by id.
    assert!(
        SdfLines
            .kernels()
            .iter()
            .all(|k| k.kernel().starts_with("sdfl_"))
    );
    let text = v.explain(1, 2);
    assert!(text.contains("sdf_lines"), "{text}");
}

#[test]
fn outputs_decide_the_drawing_passes() {
    use shapecue::scene::planner::{Outputs, plan_for};
    use shapecue::spec::edges::CapMode;
    use shapecue::spec::visibility::VisibilityMethod::{Depth, Exact};
    let out = |raster, vector, visibility| Outputs {
        raster,
        vector,
        visibility,
        pieces: false,
        fields: false,
        npz: false,
    };
    let cues = [Cue::Shading, Cue::Contours, Cue::FeatureEdges];
    for input in INPUTS {
        let p = |o| plan_for(&cues, input, CapMode::Adjacency, o);
        // A raster image only: as before, no vector pass.
        let png = p(Outputs::RASTER);
        assert_eq!(png, plan(&cues, input));
        assert!(png.contains(Pass::Render) && !png.contains(Pass::Svg));
        assert!(!png.contains(Pass::Bvh) && !png.contains(Pass::Visibility));
        // An SVG with exact visibility: no render (no GL), no caps, no
        // shading normals; the BVH per pose and the visibility per view.
        // Each pass planned or not, as listed.
        let planned = |plan: &shapecue::scene::planner::Plan, what: &str, list: &[(Pass, bool)]| {
            for &(pass, on) in list {
                assert_eq!(plan.contains(pass), on, "{what} {input:?} {pass:?}");
            }
        };
        let svg = p(out(false, true, Exact));
        planned(
            &svg,
            "svg",
            &[
                (Pass::Render, false),
                (Pass::Caps, false),
                (Pass::CapBuffer, false),
                (Pass::Bvh, true),
                (Pass::Visibility, true),
                (Pass::Svg, true),
                (Pass::Edges, true),
                (Pass::Contours, true),
            ],
        );
        assert_eq!(svg.reads(Pass::Svg), vec![Pass::Visibility]);
        let reads = svg.reads(Pass::Visibility);
        assert!(reads.contains(&Pass::Bvh) && reads.contains(&Pass::Contours));
        assert!(reads.contains(&Pass::Edges));
        // Depth visibility needs the frame, not the tree.
        let depth = p(out(false, true, Depth));
        assert!(depth.contains(Pass::Render) && depth.contains(Pass::Svg));
        assert!(!depth.contains(Pass::Bvh) && !depth.contains(Pass::Visibility));
        assert_eq!(depth.reads(Pass::Svg), vec![Pass::Render]);
        // Both: the frame with its caps, and the exact SVG.
        let both = p(out(true, true, Exact));
        assert!(both.contains(Pass::Render) && both.contains(Pass::Caps));
        assert!(both.contains(Pass::Visibility));
        // Shading alone in an SVG: nothing to classify.
        let shade = plan_for(
            &[Cue::Shading],
            input,
            CapMode::Adjacency,
            out(false, true, Exact),
        );
        assert!(!shade.contains(Pass::Visibility) && !shade.contains(Pass::VertexNormals));
        assert!(shade.contains(Pass::Svg));
        // The pieces without an SVG: exact visibility is a plan of its own
        // (the BVH and the visibility pass, no SVG pass, no render, no GL);
        // none with the depth-buffer method, none without lines.
        let pieces = |raster, visibility| Outputs {
            pieces: true,
            ..out(raster, false, visibility)
        };
        planned(
            &p(pieces(false, Exact)),
            "pieces",
            &[
                (Pass::Render, false),
                (Pass::Svg, false),
                (Pass::Bvh, true),
                (Pass::Visibility, true),
                (Pass::Contours, true),
                (Pass::Edges, true),
            ],
        );
        let with_png = p(pieces(true, Exact));
        assert!(with_png.contains(Pass::Render) && with_png.contains(Pass::Visibility));
        assert!(!with_png.contains(Pass::Svg));
        assert!(!p(pieces(false, Depth)).contains(Pass::Visibility));
        let shade_pieces = plan_for(
            &[Cue::Shading],
            input,
            CapMode::Adjacency,
            pieces(false, Exact),
        );
        assert!(!shade_pieces.contains(Pass::Visibility));
        // The view fields: read after the line passes, with the curvature's
        // derivative and the view terms; none for shading or edges alone.
        let fields = Outputs {
            fields: true,
            npz: false,
            ..out(false, true, Exact)
        };
        let f = plan_for(&cues, input, CapMode::Adjacency, fields);
        assert!(f.contains(Pass::ViewFields) && f.contains(Pass::LinesView));
        assert!(f.contains(Pass::Dcurv));
        assert!(!svg.contains(Pass::ViewFields) && !svg.contains(Pass::LinesView));
        assert_eq!(Pass::ViewFields.lifetime(input), Lifetime::View);
        let edges = plan_for(&[Cue::FeatureEdges], input, CapMode::Adjacency, fields);
        assert!(!edges.contains(Pass::ViewFields) && !edges.contains(Pass::Dcurv));
        // Lifetimes: the tree per pose, the classification per view.
        assert_eq!(Pass::Bvh.lifetime(input), Lifetime::Pose);
        assert_eq!(Pass::Visibility.lifetime(input), Lifetime::View);
    }
    // A volume's tree is built on its isosurface.
    let v = plan_for(
        &[Cue::CurvatureStrokes],
        Input::Volume,
        CapMode::Adjacency,
        out(false, true, Exact),
    );
    assert!(v.contains(Pass::Isosurface) && v.contains(Pass::Bvh));
}
