//! 2 × 2 max pooling with stride 2, as one direct loop in place of tract's general pooling.
//!
//! FaceMesh, BlazeFace and Iris halve their feature maps with 2 × 2, stride-2 max pools (NCHW,
//! nothing padded: every map they pool has even sides). tract runs every pool through its
//! general patch iterator, a few nanoseconds per output value; measured per operation
//! (`benchmarks/face.md`) FaceMesh's five pools took about a seventh of its time. Here each
//! output is the larger of two row pairs read side by side, which the compiler vectorises.
//!
//! [`replace_in`] swaps the op into an already optimised model, so no optimisation pass ever
//! sees it; pools of any other shape, stride, layout, padding or type keep tract's own op. The
//! result equals tract's to the bit (a maximum of the same four values). Pure computation on
//! tensors the model owns; no state, no panics (shape mismatches are tract errors).

use tract_onnx::prelude::*;
use tract_onnx::tract_core::internal::*;
use tract_onnx::tract_core::ops::cnn::{OptMaxPool, PoolSpec};
use tract_onnx::tract_core::ops::nn::DataFormat;

/// Max over 2 × 2 blocks of an `[N, C, H, W]` f32 tensor with even `H` and `W`.
#[derive(Debug, Clone, Default, Hash, PartialEq, Eq)]
pub(crate) struct MaxPool2x2;

impl Op for MaxPool2x2 {
    fn name(&self) -> StaticName {
        "MaxPool2x2".into()
    }

    op_as_typed_op!();
}

impl EvalOp for MaxPool2x2 {
    op_out_of_plan!();

    fn eval(&self, _ctx: &EvalContext, inputs: TVec<TValue>) -> TractResult<TVec<TValue>> {
        let input = args_1!(inputs);
        let &[n, c, h, w] = input.shape() else {
            bail!("MaxPool2x2 takes a rank-4 tensor, got shape {:?}", input.shape());
        };
        ensure!(h % 2 == 0 && w % 2 == 0, "MaxPool2x2 needs even sides, got {h} × {w}");
        let plain = input.try_as_plain_ram()?;
        let x = plain.as_slice::<f32>()?;
        let (oh, ow) = (h / 2, w / 2);
        let mut out = vec![0f32; n * c * oh * ow];
        // Each output row is the maximum of two input rows, each pair of columns.
        for (plane, out_plane) in x.chunks_exact(h * w).zip(out.chunks_exact_mut(oh * ow)) {
            for (rows, out_row) in plane.chunks_exact(2 * w).zip(out_plane.chunks_exact_mut(ow)) {
                let (upper, lower) = rows.split_at(w);
                for ((o, a), b) in out_row.iter_mut().zip(upper.chunks_exact(2)).zip(lower.chunks_exact(2)) {
                    *o = a[0].max(a[1]).max(b[0].max(b[1]));
                }
            }
        }
        Ok(tvec!(Tensor::from_shape(&[n, c, oh, ow], &out)?.into_tvalue()))
    }
}

impl TypedOp for MaxPool2x2 {
    fn output_facts(&self, inputs: &[&TypedFact]) -> TractResult<TVec<TypedFact>> {
        let shape = inputs[0]
            .shape
            .as_concrete()
            .ok_or_else(|| format_err!("MaxPool2x2 needs a concrete shape"))?;
        let &[n, c, h, w] = shape else {
            bail!("MaxPool2x2 takes a rank-4 tensor, got shape {shape:?}");
        };
        Ok(tvec!(f32::fact([n, c, h / 2, w / 2])))
    }

    as_op!();
}

/// Whether tract's pool `spec` over `input` is a plain 2 × 2, stride-2 pool that [`MaxPool2x2`]
/// computes exactly: NCHW f32 with even sides (so neither valid nor same padding pads anything).
fn is_plain_2x2(spec: &PoolSpec, with_index_outputs: bool, input: &TypedFact, output: &TypedFact) -> bool {
    let twos = |v: &[usize]| v == [2, 2];
    let ones = |v: Option<&TVec<usize>>| v.is_none_or(|d| d.iter().all(|&k| k == 1));
    let Some(&[n, c, h, w]) = input.shape.as_concrete() else {
        return false;
    };
    spec.data_format == DataFormat::NCHW
        && !with_index_outputs
        && input.datum_type == f32::datum_type()
        && twos(&spec.kernel_shape)
        && spec.strides.as_ref().is_some_and(|s| twos(s))
        && ones(spec.dilations.as_ref())
        && h % 2 == 0
        && w % 2 == 0
        && output.shape.as_concrete() == Some(&[n, c, h / 2, w / 2][..])
}

/// Replaces every plain 2 × 2, stride-2 max pool of an optimised `model` by [`MaxPool2x2`];
/// returns how many were replaced.
pub(crate) fn replace_in(model: &mut TypedModel) -> TractResult<usize> {
    let mut replaced = 0;
    for id in 0..model.nodes().len() {
        let node = &model.nodes()[id];
        let Some(pool) = node.op_as::<OptMaxPool>() else {
            continue;
        };
        let &[input] = &node.inputs[..] else {
            continue;
        };
        if !is_plain_2x2(
            &pool.pool_spec,
            pool.with_index_outputs.is_some(),
            model.outlet_fact(input)?,
            &node.outputs[0].fact,
        ) {
            continue;
        }
        let patch = TypedModelPatch::replace_single_op(model, node, &[input], MaxPool2x2)?;
        patch.apply(model)?;
        replaced += 1;
    }
    Ok(replaced)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tract_onnx::tract_core::ops::cnn::{MaxPool, PaddingSpec};

    /// A one-pool model over `[1, c, h, w]`, optimised by tract; with `ours`, its plain pools
    /// replaced. Returns the output and how many were replaced.
    fn run(
        shape: [usize; 4],
        kernel: usize,
        stride: usize,
        padding: PaddingSpec,
        x: &[f32],
        ours: bool,
    ) -> (Vec<f32>, usize) {
        let mut model = TypedModel::default();
        let source = model.add_source("x", f32::fact(shape)).expect("source");
        let pool = MaxPool {
            pool_spec: PoolSpec {
                data_format: DataFormat::NCHW,
                kernel_shape: tvec!(kernel, kernel),
                padding,
                dilations: None,
                strides: Some(tvec!(stride, stride)),
                input_channels: shape[1],
                output_channels: shape[1],
            },
            with_index_outputs: None,
        };
        let y = model.wire_node("pool", pool, &[source]).expect("wire")[0];
        model.select_output_outlets(&[y]).expect("output");
        let mut model = model.into_optimized().expect("optimised");
        assert!(
            model.nodes().iter().any(|n| n.op_is::<OptMaxPool>()),
            "tract's own pool first"
        );
        let replaced = if ours {
            replace_in(&mut model).expect("replaced")
        } else {
            0
        };
        model.compact().expect("compact");
        let plan = model.into_runnable().expect("runnable");
        let input = Tensor::from_shape(&shape, x).expect("shape");
        let out = plan.run(tvec!(input.into())).expect("runs");
        let values = out[0]
            .to_plain_array_view::<f32>()
            .expect("f32")
            .iter()
            .copied()
            .collect();
        (values, replaced)
    }

    fn input(n: usize) -> Vec<f32> {
        // Ties, negatives and a spread of magnitudes, in no order a pool could depend on.
        (0..n).map(|i| (((i * 7919) % 97) as f32 - 48.0) * 0.37).collect()
    }

    #[test]
    fn the_direct_pool_equals_tracts_to_the_bit() {
        for (shape, padding) in [
            ([1, 3, 8, 6], PaddingSpec::Valid),
            ([1, 16, 96, 96], PaddingSpec::Valid),
            ([2, 5, 4, 10], PaddingSpec::SameUpper),
        ] {
            let x = input(shape.iter().product());
            let (stock, none) = run(shape, 2, 2, padding.clone(), &x, false);
            let (ours, one) = run(shape, 2, 2, padding, &x, true);
            assert_eq!((none, one), (0, 1), "{shape:?}: one pool replaced");
            assert_eq!(ours, stock, "{shape:?}");
            // And the values are the 2 × 2 maxima (tract and ours could share a mistake).
            let [_, _, h, w] = shape;
            assert_eq!(ours[0], x[0].max(x[1]).max(x[w]).max(x[w + 1]));
            assert_eq!(ours.len(), x.len() / 4, "{h} × {w} halved");
        }
    }

    #[test]
    fn other_pools_keep_tracts_op() {
        for (shape, kernel, stride, padding) in [
            // Odd sides: same padding pads a row and a column.
            ([1, 2, 7, 7], 2, 2, PaddingSpec::SameUpper),
            // Overlapping windows.
            ([1, 2, 8, 8], 3, 2, PaddingSpec::Valid),
            ([1, 2, 8, 8], 2, 1, PaddingSpec::Valid),
        ] {
            let x = input(shape.iter().product());
            let (stock, _) = run(shape, kernel, stride, padding.clone(), &x, false);
            let (ours, replaced) = run(shape, kernel, stride, padding, &x, true);
            assert_eq!(replaced, 0, "{shape:?} kernel {kernel} stride {stride}");
            assert_eq!(ours, stock);
        }
    }
}
