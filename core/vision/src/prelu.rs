//! PReLU for tract, as one pass over the tensor.
//!
//! FaceMesh and Iris use PReLU (`y = x` for `x > 0`, `slope · x` otherwise, one slope per
//! channel) after most convolutions: 23 and 53 of them. tract-onnx imports it as a comparison, a
//! select and a multiplication, and its comparison is not vectorised: measured here it took 35
//! and 45 % of the two networks' time (`benchmarks/face.md`). Built from tract's vectorised
//! binary operations instead (`max(x, slope · x)` when every slope is at most 1, or
//! `max(x, 0) + slope · min(x, 0)`), it still read and wrote every activation twice: about a
//! sixth of the iris network's time, measured per operation. [`ChannelPrelu`] does it in one
//! pass, in place, for the constant per-channel slopes MediaPipe's networks have; slopes that are
//! not constants keep the general form of tract's operations. The results are the same to the
//! bit (one rounding, the multiplication, in each form).
//!
//! Installed by [`register`] in place of tract-onnx's own PReLU; pure computation on tensors
//! the model owns, no state, no panics (malformed models are tract errors).

use std::sync::Arc;

use tract_onnx::prelude::*;
use tract_onnx::tract_core;
use tract_onnx::tract_core::internal::{AxisChangeConsequence, AxisOp, InOut};
use tract_onnx::tract_hir::internal::*;

/// PReLU as [`ChannelPrelu`] or tract's `max`/`min`/`mul`/`add` (see the module docs).
#[derive(Debug, Clone, Hash)]
struct FastPrelu;

/// `y = x` for `x > 0`, `slopes[c] · x` otherwise, `c` the index along `axis`; one slope for
/// the whole tensor when `slopes` has one value.
#[derive(Debug, Clone, Hash, PartialEq, Eq)]
pub(crate) struct ChannelPrelu {
    axis: usize,
    /// Bit patterns of the slopes (f32 is neither `Hash` nor `Eq`).
    slopes: Arc<[u32]>,
}

impl Op for ChannelPrelu {
    fn name(&self) -> StaticName {
        "ChannelPrelu".into()
    }

    op_as_typed_op!();
}

impl EvalOp for ChannelPrelu {
    op_out_of_plan!();

    fn eval(&self, _ctx: &EvalContext, inputs: TVec<TValue>) -> TractResult<TVec<TValue>> {
        let input = args_1!(inputs);
        let shape = input.shape().to_vec();
        let channels = shape.get(self.axis).copied().unwrap_or(1);
        ensure!(
            self.slopes.len() == 1 || self.slopes.len() == channels,
            "PReLU: {} slopes for {channels} channels",
            self.slopes.len()
        );
        let inner: usize = shape.iter().skip(self.axis + 1).product();
        let mut output = input.into_tensor();
        let mut plain = output.try_as_plain_ram_mut()?;
        let values = plain.as_slice_mut::<f32>()?;
        if inner == 0 {
            return Ok(tvec!(output.into_tvalue()));
        }
        for (k, run) in values.chunks_mut(inner).enumerate() {
            let slope = f32::from_bits(self.slopes[if self.slopes.len() == 1 { 0 } else { k % channels }]);
            for v in run {
                *v = if *v > 0.0 { *v } else { slope * *v };
            }
        }
        Ok(tvec!(output.into_tvalue()))
    }
}

impl TypedOp for ChannelPrelu {
    fn output_facts(&self, inputs: &[&TypedFact]) -> TractResult<TVec<TypedFact>> {
        ensure!(inputs[0].datum_type == f32::datum_type(), "PReLU: f32 only");
        Ok(tvec!(inputs[0].without_value()))
    }

    fn axes_mapping(&self, inputs: &[&TypedFact], outputs: &[&TypedFact]) -> TractResult<AxesMapping> {
        AxesMapping::natural(inputs, outputs)
    }

    // tract drops the batch axis and moves others while optimising: the channel axis follows.
    fn change_axes(
        &self,
        model: &TypedModel,
        node: &TypedNode,
        _io: InOut,
        change: &AxisOp,
    ) -> TractResult<Option<AxisChangeConsequence>> {
        // One slope for the whole tensor does not care where its axis went.
        let axis = if self.slopes.len() == 1 {
            Some(0)
        } else {
            change.transform_axis(self.axis)
        };
        let Some(axis) = axis else {
            return Ok(None);
        };
        let op = ChannelPrelu { axis, ..self.clone() };
        Ok(Some(AxisChangeConsequence::new(
            model,
            node,
            Some(Box::new(op)),
            change,
        )))
    }

    as_op!();
}

/// The constant slopes of a PReLU over a rank-`rank` input as a [`ChannelPrelu`]: one slope, or
/// one per index of the single axis they vary along. `None` when not constant, not f32 or
/// varying along more than one axis.
fn channel_prelu(slope: &TypedFact, rank: usize) -> Option<ChannelPrelu> {
    let konst = slope.konst.as_ref()?;
    let values = konst.to_plain_array_view::<f32>().ok()?;
    let shape = konst.shape();
    // ONNX broadcasts from the right: the slope's last axis is the input's last.
    let offset = rank.checked_sub(shape.len())?;
    let varying: Vec<usize> = shape
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 1)
        .map(|(k, _)| k)
        .collect();
    let axis = match varying.as_slice() {
        [] => 0,
        [k] => offset + k,
        _ => return None,
    };
    Some(ChannelPrelu {
        axis,
        slopes: values.iter().map(|s| s.to_bits()).collect(),
    })
}

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
        if model.outlet_fact(x)?.datum_type == f32::datum_type()
            && let Some(op) = channel_prelu(model.outlet_fact(slope)?, rank)
        {
            return model.wire_node(name, op, &[x]);
        }
        // Slopes broadcast from the left (ONNX's unidirectional broadcasting).
        while model.outlet_fact(slope)?.rank() < rank {
            let r = model.outlet_fact(slope)?.rank();
            slope = model.wire_node(format!("{name}.add-axis-{r}"), AxisOp::Add(0), &[slope])?[0];
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
    fn run(slopes: &[f32], x: &[f32], fast: bool, slopes_as_input: bool) -> Vec<f32> {
        run_over(slopes, x, slopes.len(), fast, slopes_as_input)
    }

    /// As [`run`] over `channels` channels: `slopes` has one value per channel, or one for all.
    fn run_over(slopes: &[f32], x: &[f32], channels: usize, fast: bool, slopes_as_input: bool) -> Vec<f32> {
        use tract_onnx::pb;
        let (c, k) = (channels as i64, slopes.len() as i64);
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
            initializer: if slopes_as_input {
                vec![]
            } else {
                vec![pb::TensorProto {
                    dims: vec![k, 1],
                    data_type: pb::tensor_proto::DataType::Float as i32,
                    float_data: slopes.to_vec(),
                    name: "slope".into(),
                    ..Default::default()
                }]
            },
            input: if slopes_as_input {
                vec![value("x", &[1, c, n]), value("slope", &[k, 1])]
            } else {
                vec![value("x", &[1, c, n])]
            },
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
        let kinds: Vec<String> = plan.model().nodes().iter().map(|n| n.op().name().to_string()).collect();
        assert_eq!(
            kinds.iter().any(|k| k == "ChannelPrelu"),
            fast && !slopes_as_input,
            "one pass exactly for constant slopes: {kinds:?}"
        );
        let input = Tensor::from_shape(&[1, c as usize, n as usize], x).expect("shape");
        let mut inputs = tvec!(input.into());
        if slopes_as_input {
            inputs.push(Tensor::from_shape(&[k as usize, 1], slopes).expect("slopes").into());
        }
        let out = plan.run(inputs).expect("runs");
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
            // All at most 1 (including negative slopes).
            [0.25, -0.5, 1.0, 0.0],
            // All at least 1.
            [1.0, 2.5, 1.5, 3.0],
            // Mixed.
            [0.25, 2.0, -1.0, 1.0],
        ] {
            let want: Vec<f32> = x
                .chunks(6)
                .zip(slopes)
                .flat_map(|(row, s)| row.iter().map(move |v| if *v > 0.0 { *v } else { s * v }))
                .collect();
            let stock = run(&slopes, &x, false, false);
            let fast = run(&slopes, &x, true, false);
            // Slopes computed in the graph rather than stored take tract's operations.
            let general = run(&slopes, &x, true, true);
            assert_eq!(stock, want, "slopes {slopes:?}: tract's own");
            assert_eq!(fast, want, "slopes {slopes:?}: ours, one pass");
            assert_eq!(general, want, "slopes {slopes:?}: ours, general form");
        }
        // One slope for every channel.
        let want: Vec<f32> = x.iter().map(|v| if *v > 0.0 { *v } else { -0.75 * v }).collect();
        assert_eq!(run_over(&[-0.75], &x, 4, true, false), want, "one slope, one pass");
        assert_eq!(run_over(&[-0.75], &x, 4, false, false), want, "one slope, tract's own");
    }
}
