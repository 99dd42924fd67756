//! PReLU for tract, wired as cheap elementwise operations.
//!
//! FaceMesh and Iris use PReLU (`y = x` for `x > 0`, `slope · x` otherwise, one slope per
//! channel) after most convolutions: 23 and 53 of them. tract-onnx imports it as a comparison, a
//! select and a multiplication, and its comparison is not vectorised: measured here it took 35
//! and 45 % of the two networks' time (`benchmarks/face.md`). The same function is
//! `max(x, slope · x)` when every slope is at most 1 (for `x ≥ 0` the larger is `x`; for `x < 0`
//! it is `slope · x`) and `min(x, slope · x)` when every slope is at least 1; otherwise
//! `max(x, 0) + slope · min(x, 0)`. tract runs these as fused, vectorised binary operations, and
//! the results are the same to the bit (one rounding, the multiplication, in each form).
//!
//! Installed by [`register`] in place of tract-onnx's own PReLU; pure model construction, no
//! state, no panics (malformed models are tract errors).

use tract_onnx::prelude::*;
use tract_onnx::tract_core;
use tract_onnx::tract_hir::internal::*;

/// PReLU as `max`/`min`/`mul`/`add` (see the module docs).
#[derive(Debug, Clone, Hash)]
struct FastPrelu;

impl Expansion for FastPrelu {
    fn name(&self) -> StaticName {
        "FastPrelu".into()
    }

    fn rules<'r, 'p: 'r, 's: 'r>(
        &'s self,
        s: &mut Solver<'r>,
        inputs: &'p [TensorProxy],
        outputs: &'p [TensorProxy],
    ) -> InferenceResult {
        check_input_arity(inputs, 2)?;
        check_output_arity(outputs, 1)?;
        s.equals(&inputs[0].datum_type, &outputs[0].datum_type)?;
        s.equals(&inputs[0].shape, &outputs[0].shape)?;
        Ok(())
    }

    fn wire(&self, name: &str, model: &mut TypedModel, inputs: &[OutletId]) -> TractResult<TVec<OutletId>> {
        let &[x, mut slope] = inputs else {
            bail!("PReLU takes two inputs, got {}", inputs.len());
        };
        let rank = model.outlet_fact(x)?.rank();
        // Slopes broadcast from the left (ONNX's unidirectional broadcasting).
        while model.outlet_fact(slope)?.rank() < rank {
            let r = model.outlet_fact(slope)?.rank();
            slope = model.wire_node(format!("{name}.add-axis-{r}"), AxisOp::Add(0), &[slope])?[0];
        }
        // Which form holds depends on the slopes, known when they are constants (they are in
        // MediaPipe's networks); unknown slopes take the general form.
        let bound = |all: fn(f32) -> bool| {
            model
                .outlet_fact(slope)
                .ok()
                .and_then(|f| f.konst.clone())
                .and_then(|k| k.to_plain_array_view::<f32>().ok().map(|v| v.iter().all(|s| all(*s))))
                .unwrap_or(false)
        };
        let (at_most_one, at_least_one) = (bound(|s| s <= 1.0), bound(|s| s >= 1.0));
        if at_most_one || at_least_one {
            let scaled = model.wire_node(format!("{name}.scaled"), tract_core::ops::math::mul(), &[x, slope])?[0];
            let pick = if at_most_one {
                tract_core::ops::math::max()
            } else {
                tract_core::ops::math::min()
            };
            return model.wire_node(format!("{name}.pick"), pick, &[x, scaled]);
        }
        let zero = tensor0(0.0f32)
            .cast_to_dt(model.outlet_fact(x)?.datum_type)?
            .into_owned()
            .broadcast_into_rank(rank)?;
        let zero = model.add_const(format!("{name}.zero"), zero)?;
        let positive = model.wire_node(format!("{name}.positive"), tract_core::ops::math::max(), &[x, zero])?[0];
        let negative = model.wire_node(format!("{name}.negative"), tract_core::ops::math::min(), &[x, zero])?[0];
        let scaled = model.wire_node(
            format!("{name}.scaled"),
            tract_core::ops::math::mul(),
            &[negative, slope],
        )?[0];
        model.wire_node(format!("{name}.sum"), tract_core::ops::math::add(), &[positive, scaled])
    }
}

/// Makes `onnx` import PReLU as [`FastPrelu`].
pub(crate) fn register(onnx: &mut tract_onnx::Onnx) {
    onnx.op_register.insert("PRelu", |_, _| {
        Ok((tract_onnx::tract_hir::ops::expandable::expand(FastPrelu), vec![]))
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-node ONNX model `y = PRelu(x, slope)` built in memory, run by tract with and
    /// without [`register`].
    fn run(slopes: &[f32], x: &[f32], fast: bool) -> Vec<f32> {
        use tract_onnx::pb;
        let c = slopes.len() as i64;
        let value = |name: &str, dims: &[i64]| pb::ValueInfoProto {
            name: name.into(),
            r#type: Some(pb::TypeProto {
                denotation: String::new(),
                value: Some(pb::type_proto::Value::TensorType(pb::type_proto::Tensor {
                    elem_type: pb::tensor_proto::DataType::Float as i32,
                    shape: Some(pb::TensorShapeProto {
                        dim: dims
                            .iter()
                            .map(|d| pb::tensor_shape_proto::Dimension {
                                denotation: String::new(),
                                value: Some(pb::tensor_shape_proto::dimension::Value::DimValue(*d)),
                            })
                            .collect(),
                    }),
                })),
            }),
            doc_string: String::new(),
        };
        let n = x.len() as i64 / c;
        let graph = pb::GraphProto {
            node: vec![pb::NodeProto {
                input: vec!["x".into(), "slope".into()],
                output: vec!["y".into()],
                op_type: "PRelu".into(),
                ..Default::default()
            }],
            initializer: vec![pb::TensorProto {
                dims: vec![c, 1],
                data_type: pb::tensor_proto::DataType::Float as i32,
                float_data: slopes.to_vec(),
                name: "slope".into(),
                ..Default::default()
            }],
            input: vec![value("x", &[1, c, n])],
            output: vec![value("y", &[1, c, n])],
            ..Default::default()
        };
        let proto = pb::ModelProto {
            ir_version: 7,
            opset_import: vec![pb::OperatorSetIdProto {
                domain: String::new(),
                version: 13,
            }],
            graph: Some(graph),
            ..Default::default()
        };
        let mut onnx = tract_onnx::onnx();
        if fast {
            register(&mut onnx);
        }
        let plan = onnx
            .model_for_proto_model(&proto)
            .and_then(|m| m.into_optimized())
            .and_then(|m| m.into_runnable())
            .expect("a runnable model");
        let input = Tensor::from_shape(&[1, c as usize, n as usize], x).expect("shape");
        let out = plan.run(tvec!(input.into())).expect("runs");
        out[0]
            .to_plain_array_view::<f32>()
            .expect("f32")
            .iter()
            .copied()
            .collect()
    }

    #[test]
    fn every_form_equals_tracts_own_prelu_to_the_bit() {
        let x: Vec<f32> = (0..4 * 6).map(|i| (i as f32 - 11.3) * 0.37).collect();
        for slopes in [
            // All at most 1 (including negative slopes): max(x, s·x).
            [0.25, -0.5, 1.0, 0.0],
            // All at least 1: min(x, s·x).
            [1.0, 2.5, 1.5, 3.0],
            // Mixed: the general form.
            [0.25, 2.0, -1.0, 1.0],
        ] {
            let want: Vec<f32> = x
                .chunks(6)
                .zip(slopes)
                .flat_map(|(row, s)| row.iter().map(move |v| if *v > 0.0 { *v } else { s * v }))
                .collect();
            let stock = run(&slopes, &x, false);
            let fast = run(&slopes, &x, true);
            assert_eq!(stock, want, "slopes {slopes:?}: tract's own");
            assert_eq!(fast, want, "slopes {slopes:?}: ours");
        }
    }
}
