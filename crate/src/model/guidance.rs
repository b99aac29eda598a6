//! Classifier-free guidance: each step of the unmasking loop runs a transformer twice, with the
//! text (conditional) and without it (unconditional), and samples from
//! `(1 + s)·cond − s·uncond`. This module decides where the two passes run: side by side on
//! two cores natively, on a [`GuidancePartner`] (the page's second worker) when one is set,
//! else as one batch of two.

use super::transformer::{BaseTransformer, ResidualTransformer, PARTS, TEXT_DIM};
use super::Spam;
use burn::prelude::*;
use burn::tensor::{Bool, Int, TensorData};
use serde::{Deserialize, Serialize};
use std::future::Future;
use std::pin::Pin;

/// One call of a transformer in the unmasking loop, without its text: what the unconditional
/// pass needs, and all a [`GuidancePartner`] is sent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pass {
    /// 0: the base transformer over `tokens` `[4, N]` (codes and mask ids); `j ≥ 1`: the
    /// residual transformer predicting layer `j` from `tokens` `[4, j, N]` (layers `0..j`).
    pub layer: usize,
    /// `N`, time steps of 4 frames (0.2 s at 20 fps).
    pub steps: usize,
    /// Token ids, part-major.
    pub tokens: Vec<i32>,
}

/// Future of a partner's logits, or why it has none.
pub type PartnerReply = Pin<Box<dyn Future<Output = Result<Vec<f32>, String>>>>;

/// Somewhere else that runs guidance's unconditional pass while this thread runs the
/// conditional one. The page's CPU backend has one thread (wasm threads need cross-origin
/// isolation and a separate build without WebGPU), so its second core is a second worker
/// holding the same transformers (`web/src/partner.rs`); natively rayon's second thread does
/// the same without one.
pub trait GuidancePartner: std::fmt::Debug {
    /// Sends `pass` at once (before returning, so both passes run at the same time) and
    /// resolves to its unconditional logits `[4, N, K]`, flattened, as
    /// [`Spam::unconditional_logits`] computes them.
    fn unconditional(&self, pass: &Pass) -> PartnerReply;
}

/// What every pass of one motion shares: its text `[1, 4, 384]` and no padding `[1, N]`.
pub(crate) struct PassInputs {
    text: Tensor<3>,
    pad: Tensor<2, Bool>,
}

impl PassInputs {
    pub(crate) fn new(text: &[[f32; TEXT_DIM]; PARTS], steps: usize, device: &Device) -> Self {
        let flat: Vec<f32> = text.iter().flatten().copied().collect();
        PassInputs {
            text: Tensor::from_data(TensorData::new(flat, [1, PARTS, TEXT_DIM]), device),
            pad: Tensor::<2, Int>::zeros([1, steps], device).equal_elem(1),
        }
    }
}

/// The transformers, borrowed from [`Spam`] so both passes can share them across threads.
#[derive(Clone, Copy)]
struct Transformers<'a> {
    base: &'a BaseTransformer,
    residual: Option<&'a ResidualTransformer>,
    device: &'a Device,
}

impl Transformers<'_> {
    /// Logits `[C, 4, N, K]` of `pass` for keep-text flags `keep` `[C, 4]` (1 keeps the text,
    /// 0 drops it for the null condition), on `C` copies of the pass.
    fn logits(&self, pass: &Pass, inputs: &PassInputs, keep: Tensor<2>) -> Tensor<4> {
        let copies = keep.dims()[0];
        let (n, device) = (pass.steps, self.device);
        let text = inputs.text.clone().repeat_dim(0, copies);
        let pad = inputs.pad.clone().repeat_dim(0, copies);
        let ids = TensorData::new(pass.tokens.clone(), [1, PARTS, pass.layer.max(1) * n]);
        let tokens = Tensor::<3, Int>::from_data(ids, device);
        match (pass.layer, self.residual) {
            (0, _) => self
                .base
                .forward(tokens.repeat_dim(0, copies), text, keep, pad),
            (j, Some(residual)) => {
                let lower = tokens.reshape([1, PARTS, j, n]).repeat_dim(0, copies);
                residual.forward(lower, j, text, keep, pad)
            }
            (_, None) => unreachable!("Pass::check refuses residual passes of a base-only model"),
        }
    }

    fn keep(&self, value: f32) -> Tensor<2> {
        Tensor::from_data(TensorData::new(vec![value; PARTS], [1, PARTS]), self.device)
    }
}

/// `(1 + s)·cond − s·uncond`, element by element.
fn combine(cond: &[f32], uncond: &[f32], scale: f32) -> Vec<f32> {
    cond.iter()
        .zip(uncond)
        .map(|(c, u)| (1.0 + scale) * c - scale * u)
        .collect()
}

impl Spam {
    fn transformers(&self) -> Transformers<'_> {
        Transformers {
            base: &self.base,
            residual: self.residual.as_ref().map(|r| &r.network),
            device: &self.device,
        }
    }

    /// Whether `pass` fits this model: a network it has, `steps` within its range, as many
    /// ids as the pass says and every id a code, the mask or padding.
    pub fn check_pass(&self, pass: &Pass) -> Result<(), String> {
        let config = match (pass.layer, &self.residual) {
            (0, _) => &self.base_config,
            (j, Some(r)) if j < r.config.vq_layers => &r.config,
            (j, _) => return Err(format!("this model has no transformer for layer {j}")),
        };
        if pass.steps == 0 || pass.steps > config.max_steps {
            return Err(format!(
                "{} time steps: the model takes 1 to {}",
                pass.steps, config.max_steps
            ));
        }
        let want = PARTS * pass.layer.max(1) * pass.steps;
        if pass.tokens.len() != want {
            return Err(format!("{} token ids, {want} expected", pass.tokens.len()));
        }
        let last = config.pad_id() as i32;
        match pass.tokens.iter().find(|t| !(0..=last).contains(*t)) {
            Some(t) => Err(format!("token id {t} is outside 0..={last}")),
            None => Ok(()),
        }
    }

    /// The unconditional logits `[4, N, K]` (flattened) of `pass`: the text dropped for the
    /// null condition, so no text is needed. What a [`GuidancePartner`] computes.
    pub async fn unconditional_logits(&self, pass: &Pass) -> Result<Vec<f32>, String> {
        self.check_pass(pass)?;
        let nets = self.transformers();
        let inputs = PassInputs::new(&[[0.0; TEXT_DIM]; PARTS], pass.steps, &self.device);
        Ok(super::read_floats(nets.logits(pass, &inputs, nets.keep(0.0))).await)
    }

    /// Guided logits `[4, N, K]` (flattened) of `pass` at guidance scale `scale`.
    ///
    /// On the CPU device natively the two passes run at once, one per core (`rayon::join`).
    /// burn's CPU backend threads each operation on its own, and at these sizes (a few
    /// hundred rows) waking and joining the threads around every product costs much of the
    /// time (`perf record --call-graph dwarf coma bench --train-steps 0`: 13 % in system
    /// calls); two whole passes side by side take about 0.6× the time of one batch of two
    /// (`scripts/speed_reference.sh`, docs/experiments.md). With a partner the
    /// unconditional pass runs there (if it fails, here). Elsewhere (WebGPU, the page
    /// without a partner) one batch of two is one pass. All give the same logits, bit for bit
    /// on the CPU (tested).
    pub(crate) async fn guided_logits(
        &self,
        pass: &Pass,
        inputs: &PassInputs,
        scale: f32,
    ) -> Vec<f32> {
        let nets = self.transformers();
        if let Some(partner) = &self.partner {
            let remote = partner.unconditional(pass);
            let cond = super::read_floats(nets.logits(pass, inputs, nets.keep(1.0))).await;
            let uncond = match remote.await {
                Ok(uncond) if uncond.len() == cond.len() => uncond,
                _ => super::read_floats(nets.logits(pass, inputs, nets.keep(0.0))).await,
            };
            return combine(&cond, &uncond, scale);
        }
        #[cfg(not(target_arch = "wasm32"))]
        if self.device == Device::flex() {
            let (cond, uncond) = rayon::join(
                || nets.logits(pass, inputs, nets.keep(1.0)),
                || nets.logits(pass, inputs, nets.keep(0.0)),
            );
            let cond = super::read_floats(cond).await;
            return combine(&cond, &super::read_floats(uncond).await, scale);
        }
        let both = Tensor::cat(vec![nets.keep(1.0), nets.keep(0.0)], 0);
        let pair = super::read_floats(nets.logits(pass, inputs, both)).await;
        let (cond, uncond) = pair.split_at(pair.len() / 2);
        combine(cond, uncond, scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::executor::block_on;
    use crate::model::generate::tests::{small, tiny_vq};
    use crate::model::generate::SamplingOptions;
    use crate::rng::Rng;

    fn spam() -> Spam {
        Spam::random(&tiny_vq(), &small(), Some(&small()), &Device::flex())
    }

    /// A partner in the same process: another copy of the same networks, or one that fails.
    #[derive(Debug)]
    struct InProcess(Option<Spam>);

    impl GuidancePartner for InProcess {
        fn unconditional(&self, pass: &Pass) -> PartnerReply {
            let reply = match &self.0 {
                Some(spam) => block_on(spam.unconditional_logits(pass)),
                None => Err("the partner has gone".into()),
            };
            Box::pin(std::future::ready(reply))
        }
    }

    fn copy_of(spam: &Spam) -> Spam {
        let mut copy = Spam::random(&tiny_vq(), &small(), Some(&small()), &Device::flex());
        copy.vq = spam.vq.clone();
        copy.base = spam.base.clone();
        copy.residual.as_mut().unwrap().network = spam.residual.as_ref().unwrap().network.clone();
        copy
    }

    fn tokens(spam: &Spam) -> crate::model::generate::MotionTokens {
        let text = [[0.2f32; TEXT_DIM]; PARTS];
        let options = SamplingOptions {
            seed: 4,
            ..Default::default()
        };
        let mut rng = Rng::new(4);
        let base =
            block_on(spam.decode_base(&text, &vec![vec![None; 6]; PARTS], &options, &mut rng));
        block_on(spam.decode_residual(&text, base, None, &options, &mut rng))
    }

    #[test]
    fn every_place_the_passes_run_gives_the_same_tokens() {
        let alone = spam();
        let want = tokens(&alone);
        let mut helped = copy_of(&alone);
        helped.partner = Some(std::rc::Rc::new(InProcess(Some(copy_of(&alone)))));
        assert_eq!(
            tokens(&helped),
            want,
            "a partner computing the unconditional pass"
        );
        helped.partner = Some(std::rc::Rc::new(InProcess(None)));
        assert_eq!(
            tokens(&helped),
            want,
            "a failing partner: the pass runs here instead"
        );
    }

    #[test]
    fn guided_logits_agree_with_one_batch_of_two() {
        let spam = spam();
        let inputs = PassInputs::new(&[[0.3f32; TEXT_DIM]; PARTS], 5, &Device::flex());
        let pass = Pass {
            layer: 0,
            steps: 5,
            tokens: (0..PARTS as i32 * 5).map(|i| i % 17).collect(),
        };
        let got = block_on(spam.guided_logits(&pass, &inputs, 2.0));
        let nets = spam.transformers();
        let both = Tensor::cat(vec![nets.keep(1.0), nets.keep(0.0)], 0);
        let pair = block_on(crate::model::read_floats(nets.logits(&pass, &inputs, both)));
        let (cond, uncond) = pair.split_at(pair.len() / 2);
        assert_eq!(got, combine(cond, uncond, 2.0), "bit for bit");
        assert_ne!(cond, uncond, "the text changes the logits");
        let alone = block_on(spam.unconditional_logits(&pass)).unwrap();
        assert_eq!(alone, uncond, "the unconditional pass needs no text");
    }

    #[test]
    fn a_pass_that_does_not_fit_is_refused_with_the_reason() {
        let spam = Spam::random(&tiny_vq(), &small(), None, &Device::flex());
        let pass = |layer, steps, tokens: Vec<i32>| Pass {
            layer,
            steps,
            tokens,
        };
        let err = |p: Pass| block_on(spam.unconditional_logits(&p)).unwrap_err();
        assert!(err(pass(1, 2, vec![0; 8])).contains("no transformer for layer 1"));
        assert!(err(pass(0, 0, vec![])).contains("1 to 50"));
        assert!(err(pass(0, 2, vec![0; 7])).contains("7 token ids, 8 expected"));
        assert!(err(pass(0, 2, vec![0, 0, 0, 99, 0, 0, 0, 0])).contains("token id 99"));
        assert_eq!(
            block_on(spam.unconditional_logits(&pass(0, 2, vec![3; 8])))
                .unwrap()
                .len(),
            8 * 16
        );
    }
}
