//! Dormand–Prince 8(5,3) (Hairer's DOP853): explicit, adaptive, FSAL, with
//! the 7th-order continuous extension for dense output.
//!
//! The error estimate combines the embedded 5th- and 3rd-order solutions as
//! Hairer does (err₅² / √(err₅² + 0.01·err₃²)): the 3rd-order term keeps the
//! estimate honest when the 5th-order one happens to be tiny. The dense
//! output needs three extra stages per accepted step; observers always get
//! dense output, so every accepted step pays them and they are counted.
//!
//! Coefficients are Hairer's `dop853.f` digits (Prince & Dormand 1981,
//! Hairer, Nørsett & Wanner I, II.10), checked against the order conditions
//! in this file's unit test; the dense-output weights are checked by the
//! observed order of the interpolant in `tests/it/integrate.rs`.

#![allow(
    clippy::excessive_precision,
    reason = "coefficients keep the published digits so that they can be compared with the source"
)]

use super::controller::PiController;
use super::norm::{atol_of, explicit_start};
use super::stepper::{Stepper, Trial};
use super::stiffness::{PowerProbe, indicator};
use super::{DenseOutput, Failure, Method, OdeSystem, SolverOptions, Stats};

const C2: f64 = 0.526_001_519_587_677_318_785_587_544_488e-1;
const C3: f64 = 0.789_002_279_381_515_978_178_381_316_732e-1;
const C4: f64 = 0.118_350_341_907_227_396_726_757_197_510;
const C5: f64 = 0.281_649_658_092_772_603_273_242_802_490;
const C6: f64 = 0.333_333_333_333_333_333_333_333_333_333;
const C7: f64 = 0.25;
const C8: f64 = 0.307_692_307_692_307_692_307_692_307_692;
const C9: f64 = 0.651_282_051_282_051_282_051_282_051_282;
const C10: f64 = 0.6;
const C11: f64 = 0.857_142_857_142_857_142_857_142_857_142;
const C14: f64 = 0.1;
const C15: f64 = 0.2;
const C16: f64 = 0.777_777_777_777_777_777_777_777_777_778;

const B1: f64 = 5.429_373_411_656_876_223_805_357_663_63e-2;
const B6: f64 = 4.450_312_892_752_408_881_441_139_505_66;
const B7: f64 = 1.891_517_899_314_500_383_042_815_990_44;
const B8: f64 = -5.801_203_960_010_584_781_467_211_422_7;
const B9: f64 = 3.111_643_669_578_198_944_089_160_623_7e-1;
const B10: f64 = -1.521_609_496_625_160_785_561_788_068_05e-1;
const B11: f64 = 2.013_654_008_040_303_483_747_765_375_01e-1;
const B12: f64 = 4.471_061_572_777_259_051_768_855_690_43e-2;

const BHH1: f64 = 0.244_094_488_188_976_377_952_755_905_512;
const BHH2: f64 = 0.733_846_688_281_611_857_341_361_741_547;
const BHH3: f64 = 0.220_588_235_294_117_647_058_823_529_412e-1;

const ER1: f64 = 0.131_200_449_941_948_807_325_010_299_6e-1;
const ER6: f64 = -0.122_515_644_637_620_444_072_056_975_3e1;
const ER7: f64 = -0.495_758_949_657_250_191_521_407_995_2;
const ER8: f64 = 0.166_437_718_245_498_653_696_153_041_5e1;
const ER9: f64 = -0.350_328_848_749_973_681_688_648_729_0;
const ER10: f64 = 0.334_179_118_713_017_479_029_731_884_1;
const ER11: f64 = 0.819_232_064_851_157_124_657_074_261_3e-1;
const ER12: f64 = -0.223_553_078_638_862_952_588_442_784_5e-1;

const A21: f64 = 5.260_015_195_876_773_187_855_875_444_88e-2;
const A31: f64 = 1.972_505_698_453_789_945_445_953_291_83e-2;
const A32: f64 = 5.917_517_095_361_369_836_337_859_875_49e-2;
const A41: f64 = 2.958_758_547_680_684_918_168_929_937_75e-2;
const A43: f64 = 8.876_275_643_042_054_754_506_789_813_24e-2;
const A51: f64 = 2.413_651_341_592_666_855_023_697_986_65e-1;
const A53: f64 = -8.845_494_793_282_860_853_448_649_627_17e-1;
const A54: f64 = 9.248_340_032_617_920_031_157_379_665_43e-1;
const A61: f64 = 3.703_703_703_703_703_703_703_703_703_7e-2;
const A64: f64 = 1.708_286_087_294_738_712_796_044_821_73e-1;
const A65: f64 = 1.254_676_875_668_224_250_166_918_141_23e-1;
const A71: f64 = 3.710_937_5e-2;
const A74: f64 = 1.702_522_110_195_440_393_149_780_602_72e-1;
const A75: f64 = 6.021_653_898_045_596_068_502_193_972_83e-2;
const A76: f64 = -1.757_812_5e-2;
const A81: f64 = 3.709_200_011_850_479_271_087_793_198_36e-2;
const A84: f64 = 1.703_839_257_122_399_938_102_140_547_05e-1;
const A85: f64 = 1.072_620_304_463_732_846_518_091_991_68e-1;
const A86: f64 = -1.531_943_774_862_440_175_279_361_582_36e-2;
const A87: f64 = 8.273_789_163_814_022_887_584_737_660_02e-3;
const A91: f64 = 6.241_109_587_160_757_171_144_295_778_12e-1;
const A94: f64 = -3.360_892_629_446_941_294_068_571_098_25;
const A95: f64 = -8.682_193_468_417_260_068_181_898_914_53e-1;
const A96: f64 = 2.759_209_969_944_670_830_494_156_007_97e1;
const A97: f64 = 2.015_406_755_047_789_340_861_867_889_79e1;
const A98: f64 = -4.348_988_418_106_995_884_773_662_551_44e1;
const A101: f64 = 4.776_625_364_382_643_658_904_339_085_27e-1;
const A104: f64 = -2.488_114_619_971_667_641_926_425_864_68;
const A105: f64 = -5.902_908_268_368_429_963_714_464_757_43e-1;
const A106: f64 = 2.123_005_144_818_119_423_472_889_498_97e1;
const A107: f64 = 1.527_923_363_288_242_358_325_969_229_38e1;
const A108: f64 = -3.328_821_096_898_486_291_944_532_655_87e1;
const A109: f64 = -2.033_120_170_850_862_613_582_229_285_93e-2;
const A111: f64 = -9.371_424_300_859_873_257_170_402_165_8e-1;
const A114: f64 = 5.186_372_428_844_063_708_300_238_532_09;
const A115: f64 = 1.091_437_348_996_729_578_185_002_546_54;
const A116: f64 = -8.149_787_010_746_926_125_139_972_673_57;
const A117: f64 = -1.852_006_565_999_695_986_415_661_807_01e1;
const A118: f64 = 2.273_948_709_935_050_428_189_700_567_34e1;
const A119: f64 = 2.493_605_552_679_652_389_870_893_967_62;
const A1110: f64 = -3.046_764_471_898_219_500_382_366_902_2;
const A121: f64 = 2.273_310_147_516_538_207_923_597_684_49;
const A124: f64 = -1.053_449_546_673_725_019_840_666_898_79e1;
const A125: f64 = -2.000_872_058_224_862_499_096_757_184_44;
const A126: f64 = -1.795_893_186_311_879_891_727_659_505_34e1;
const A127: f64 = 2.794_888_452_941_996_005_084_998_088_37e1;
const A128: f64 = -2.858_998_277_135_023_694_740_655_086_74;
const A129: f64 = -8.872_856_933_530_629_544_335_492_892_58;
const A1210: f64 = 1.236_056_717_579_430_306_472_662_015_28e1;
const A1211: f64 = 6.433_927_460_157_635_303_559_704_840_46e-1;

const A141: f64 = 5.616_750_228_304_795_233_929_092_196_81e-2;
const A147: f64 = 2.535_002_102_166_248_110_887_947_653_33e-1;
const A148: f64 = -2.462_390_374_708_024_899_174_414_754_41e-1;
const A149: f64 = -1.241_914_232_638_163_604_690_101_406_26e-1;
const A1410: f64 = 1.532_917_982_787_656_973_120_632_268_5e-1;
const A1411: f64 = 8.201_052_295_634_689_884_916_666_020_57e-3;
const A1412: f64 = 7.567_897_660_545_699_761_386_035_895_84e-3;
const A1413: f64 = -8.298e-3;
const A151: f64 = 3.183_464_816_350_214_050_607_684_732_61e-2;
const A156: f64 = 2.830_090_967_236_677_552_883_229_614_02e-2;
const A157: f64 = 5.354_198_830_743_856_762_237_973_843_72e-2;
const A158: f64 = -5.492_374_857_139_098_846_465_693_403_06e-2;
const A1511: f64 = -1.083_473_286_972_493_228_585_093_169_94e-4;
const A1512: f64 = 3.825_710_908_356_584_129_549_201_923_23e-4;
const A1513: f64 = -3.404_650_086_874_045_608_029_771_144_92e-4;
const A1514: f64 = 1.413_124_436_746_325_002_780_746_183_66e-1;
const A161: f64 = -4.288_963_015_837_919_234_085_735_386_92e-1;
const A166: f64 = -4.697_621_415_361_163_843_144_494_472_06;
const A167: f64 = 7.683_421_196_062_599_041_842_409_538_78;
const A168: f64 = 4.068_989_818_397_110_079_702_135_543_31;
const A169: f64 = 3.567_271_874_552_811_092_706_695_430_21e-1;
const A1613: f64 = -1.399_024_165_159_014_621_294_180_097_34e-3;
const A1614: f64 = 2.947_514_789_152_772_338_955_627_214_9;
const A1615: f64 = -9.150_958_472_179_870_010_818_701_871_38;

const D41: f64 = -0.842_893_827_610_901_286_513_534_911_42e1;
const D46: f64 = 0.566_714_953_519_377_769_625_317_835_90;
const D47: f64 = -0.306_894_994_594_989_169_127_973_047_27e1;
const D48: f64 = 0.238_466_765_651_206_982_877_281_496_80e1;
const D49: f64 = 0.211_703_458_244_502_827_671_551_499_46e1;
const D410: f64 = -0.871_391_583_777_972_992_067_899_074_90;
const D411: f64 = 0.224_043_743_026_078_827_585_417_716_50e1;
const D412: f64 = 0.631_578_778_769_468_818_155_702_492_90;
const D413: f64 = -0.889_903_364_513_333_108_206_981_174_00e-1;
const D414: f64 = 0.181_485_055_208_547_272_566_564_049_62e2;
const D415: f64 = -0.919_463_239_247_835_540_004_519_844_36e1;
const D416: f64 = -0.443_603_638_759_489_396_643_105_720_00e1;
const D51: f64 = 0.104_275_086_425_791_346_034_131_510_09e2;
const D56: f64 = 0.242_283_491_775_258_182_884_301_753_19e3;
const D57: f64 = 0.165_200_451_717_270_281_985_053_948_87e3;
const D58: f64 = -0.374_546_754_722_690_202_795_183_121_52e3;
const D59: f64 = -0.221_136_668_531_253_060_362_709_385_78e2;
const D510: f64 = 0.773_343_266_847_226_383_896_038_988_08e1;
const D511: f64 = -0.306_740_847_310_893_981_820_612_136_26e2;
const D512: f64 = -0.933_213_052_643_022_787_295_672_217_06e1;
const D513: f64 = 0.156_972_381_217_708_438_861_310_910_75e2;
const D514: f64 = -0.311_394_032_195_651_776_772_828_504_11e2;
const D515: f64 = -0.935_292_435_884_447_838_657_138_626_64e1;
const D516: f64 = 0.358_168_414_863_940_837_524_658_985_40e2;
const D61: f64 = 0.199_850_532_420_024_338_209_876_536_17e2;
const D66: f64 = -0.387_037_308_749_351_765_551_059_017_42e3;
const D67: f64 = -0.189_178_138_195_167_568_828_308_383_28e3;
const D68: f64 = 0.527_808_159_205_423_649_005_610_166_86e3;
const D69: f64 = -0.115_739_025_399_596_301_261_418_711_34e2;
const D610: f64 = 0.688_123_269_469_630_001_696_669_226_61e1;
const D611: f64 = -0.100_060_509_669_108_384_031_838_609_80e1;
const D612: f64 = 0.777_713_779_805_344_320_928_692_657_40;
const D613: f64 = -0.277_820_575_235_350_840_659_320_043_39e1;
const D614: f64 = -0.601_966_952_312_641_207_582_673_808_46e2;
const D615: f64 = 0.843_204_055_066_771_610_181_599_037_84e2;
const D616: f64 = 0.119_922_911_361_827_893_280_351_300_30e2;
const D71: f64 = -0.256_939_334_627_037_490_033_125_861_29e2;
const D76: f64 = -0.154_189_748_690_236_433_740_539_936_27e3;
const D77: f64 = -0.231_529_379_176_045_495_675_360_391_09e3;
const D78: f64 = 0.357_639_117_910_614_123_782_853_499_10e3;
const D79: f64 = 0.934_053_241_836_243_100_039_076_917_04e2;
const D710: f64 = -0.374_583_231_364_516_331_568_751_393_51e2;
const D711: f64 = 0.104_099_649_508_962_300_451_472_461_84e3;
const D712: f64 = 0.298_402_934_266_605_031_233_443_635_79e2;
const D713: f64 = -0.435_334_565_900_111_437_544_321_750_58e2;
const D714: f64 = 0.963_245_539_591_882_829_483_949_506_00e2;
const D715: f64 = -0.391_772_616_756_154_391_652_314_861_72e2;
const D716: f64 = -0.149_726_836_257_985_625_814_221_252_76e3;

/// Dense-output weights of the stages 1, 6…16 for `rcont` 5…8.
const D4: [f64; 12] = [
    D41, D46, D47, D48, D49, D410, D411, D412, D413, D414, D415, D416,
];
const D5: [f64; 12] = [
    D51, D56, D57, D58, D59, D510, D511, D512, D513, D514, D515, D516,
];
const D6: [f64; 12] = [
    D61, D66, D67, D68, D69, D610, D611, D612, D613, D614, D615, D616,
];
const D7: [f64; 12] = [
    D71, D76, D77, D78, D79, D710, D711, D712, D713, D714, D715, D716,
];

#[inline]
fn dot(w: &[f64; 12], k: &[f64; 12]) -> f64 {
    w.iter().zip(k).map(|(a, b)| a * b).sum()
}

/// Step-size controller of Hairer's DOP853: safety factor, h_new/h within
/// [1/6, 3]; β = 0, i.e. a plain I controller, is Hairer's default here.
const SAFE: f64 = 0.9;
const FAC_MIN: f64 = 1.0 / 3.0;
const FAC_MAX: f64 = 6.0;

/// The 7th-order continuous extension over one step: Hairer's eight `rcont`
/// vectors, evaluated in nested form.
struct Dense {
    t_old: f64,
    h: f64,
    r: [Vec<f64>; 8],
}

impl DenseOutput for Dense {
    fn eval(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t_old) / self.h;
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5, r6, r7, r8] = &self.r;
        for i in 0..out.len() {
            out[i] = r1[i]
                + s * (r2[i]
                    + s1 * (r3[i]
                        + s * (r4[i] + s1 * (r5[i] + s * (r6[i] + s1 * (r7[i] + s * r8[i]))))));
        }
    }
}

/// Stage derivatives k1…k16 of one step (k13 is f at the accepted end point).
struct Stages {
    k: [Vec<f64>; 16],
}

/// Hairer's combined error: err₅² / √(err₅² + 0.01·err₃²), per unit step.
fn error_estimate(k: &[Vec<f64>; 16], y: &[f64], y1: &[f64], rtol: f64, atol: &[f64]) -> f64 {
    let [k1, _, _, _, _, k6, k7, k8, k9, k10, k11, k12, ..] = k;
    let (mut err5, mut err3) = (0.0, 0.0);
    for i in 0..y.len() {
        let sk = atol_of(atol, i) + rtol * y[i].abs().max(y1[i].abs());
        let bsum = B1 * k1[i]
            + B6 * k6[i]
            + B7 * k7[i]
            + B8 * k8[i]
            + B9 * k9[i]
            + B10 * k10[i]
            + B11 * k11[i]
            + B12 * k12[i];
        let e3 = (bsum - BHH1 * k1[i] - BHH2 * k9[i] - BHH3 * k12[i]) / sk;
        let e5 = (ER1 * k1[i]
            + ER6 * k6[i]
            + ER7 * k7[i]
            + ER8 * k8[i]
            + ER9 * k9[i]
            + ER10 * k10[i]
            + ER11 * k11[i]
            + ER12 * k12[i])
            / sk;
        err3 += e3 * e3;
        err5 += e5 * e5;
    }
    let deno = err5 + 0.01 * err3;
    let deno = if deno <= 0.0 { 1.0 } else { deno };
    err5 * (1.0 / (y.len() as f64 * deno)).sqrt()
}

impl Stages {
    /// Stages 2…12 of a step of size h from (t, y) with k1 already set;
    /// writes the 8th-order solution into `y1`.
    fn step<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        h: f64,
        y: &[f64],
        ys: &mut [f64],
        y1: &mut [f64],
    ) {
        let [k1, k2, k3, k4, k5, k6, k7, k8, k9, k10, k11, k12, ..] = &mut self.k;
        let n = y.len();
        for i in 0..n {
            ys[i] = y[i] + h * A21 * k1[i];
        }
        system.rhs(t + C2 * h, ys, k2);
        for i in 0..n {
            ys[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        system.rhs(t + C3 * h, ys, k3);
        for i in 0..n {
            ys[i] = y[i] + h * (A41 * k1[i] + A43 * k3[i]);
        }
        system.rhs(t + C4 * h, ys, k4);
        for i in 0..n {
            ys[i] = y[i] + h * (A51 * k1[i] + A53 * k3[i] + A54 * k4[i]);
        }
        system.rhs(t + C5 * h, ys, k5);
        for i in 0..n {
            ys[i] = y[i] + h * (A61 * k1[i] + A64 * k4[i] + A65 * k5[i]);
        }
        system.rhs(t + C6 * h, ys, k6);
        for i in 0..n {
            ys[i] = y[i] + h * (A71 * k1[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        system.rhs(t + C7 * h, ys, k7);
        for i in 0..n {
            ys[i] =
                y[i] + h * (A81 * k1[i] + A84 * k4[i] + A85 * k5[i] + A86 * k6[i] + A87 * k7[i]);
        }
        system.rhs(t + C8 * h, ys, k8);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A91 * k1[i]
                    + A94 * k4[i]
                    + A95 * k5[i]
                    + A96 * k6[i]
                    + A97 * k7[i]
                    + A98 * k8[i]);
        }
        system.rhs(t + C9 * h, ys, k9);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A101 * k1[i]
                    + A104 * k4[i]
                    + A105 * k5[i]
                    + A106 * k6[i]
                    + A107 * k7[i]
                    + A108 * k8[i]
                    + A109 * k9[i]);
        }
        system.rhs(t + C10 * h, ys, k10);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A111 * k1[i]
                    + A114 * k4[i]
                    + A115 * k5[i]
                    + A116 * k6[i]
                    + A117 * k7[i]
                    + A118 * k8[i]
                    + A119 * k9[i]
                    + A1110 * k10[i]);
        }
        system.rhs(t + C11 * h, ys, k11);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A121 * k1[i]
                    + A124 * k4[i]
                    + A125 * k5[i]
                    + A126 * k6[i]
                    + A127 * k7[i]
                    + A128 * k8[i]
                    + A129 * k9[i]
                    + A1210 * k10[i]
                    + A1211 * k11[i]);
        }
        // Stage 12 sits at c = 1: evaluate at t + h exactly, not t + C11·h.
        system.rhs(t + h, ys, k12);
        for i in 0..n {
            y1[i] = y[i]
                + h * (B1 * k1[i]
                    + B6 * k6[i]
                    + B7 * k7[i]
                    + B8 * k8[i]
                    + B9 * k9[i]
                    + B10 * k10[i]
                    + B11 * k11[i]
                    + B12 * k12[i]);
        }
    }

    /// The three extra stages and the `rcont` vectors of the continuous
    /// extension; needs k13 = f(t + h, y1) already set.
    #[allow(clippy::too_many_arguments)]
    fn dense<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        h: f64,
        y: &[f64],
        y1: &[f64],
        ys: &mut [f64],
        dense: &mut Dense,
    ) {
        let [
            k1,
            _,
            _,
            _,
            _,
            k6,
            k7,
            k8,
            k9,
            k10,
            k11,
            k12,
            k13,
            k14,
            k15,
            k16,
        ] = &mut self.k;
        let n = y.len();
        for i in 0..n {
            ys[i] = y[i]
                + h * (A141 * k1[i]
                    + A147 * k7[i]
                    + A148 * k8[i]
                    + A149 * k9[i]
                    + A1410 * k10[i]
                    + A1411 * k11[i]
                    + A1412 * k12[i]
                    + A1413 * k13[i]);
        }
        system.rhs(t + C14 * h, ys, k14);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A151 * k1[i]
                    + A156 * k6[i]
                    + A157 * k7[i]
                    + A158 * k8[i]
                    + A1511 * k11[i]
                    + A1512 * k12[i]
                    + A1513 * k13[i]
                    + A1514 * k14[i]);
        }
        system.rhs(t + C15 * h, ys, k15);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A161 * k1[i]
                    + A166 * k6[i]
                    + A167 * k7[i]
                    + A168 * k8[i]
                    + A169 * k9[i]
                    + A1613 * k13[i]
                    + A1614 * k14[i]
                    + A1615 * k15[i]);
        }
        system.rhs(t + C16 * h, ys, k16);
        let [r1, r2, r3, r4, r5, r6, r7, r8] = &mut dense.r;
        for i in 0..n {
            let ydiff = y1[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            r1[i] = y[i];
            r2[i] = ydiff;
            r3[i] = bspl;
            // k13 is the derivative at the new point, so the extension
            // matches both the state and the slope at t + h.
            r4[i] = ydiff - h * k13[i] - bspl;
            let ks = [
                k1[i], k6[i], k7[i], k8[i], k9[i], k10[i], k11[i], k12[i], k13[i], k14[i], k15[i],
                k16[i],
            ];
            r5[i] = h * dot(&D4, &ks);
            r6[i] = h * dot(&D5, &ks);
            r7[i] = h * dot(&D6, &ks);
            r8[i] = h * dot(&D7, &ks);
        }
        dense.t_old = t;
        dense.h = h;
    }
}

/// DOP853's work vectors: the stages, the trial solution, the stage
/// argument and the dense output.
pub struct Dop853 {
    options: SolverOptions,
    controller: PiController,
    st: Stages,
    y1: Vec<f64>,
    ys: Vec<f64>,
    dense: Dense,
    probe: PowerProbe,
}

impl Stepper for Dop853 {
    const METHOD: Method = Method::Dop853;
    /// Hairer's bound on h·|λ| for the stability region of DOP853.
    const STIFF_BOUND: f64 = 6.1;

    fn new(dim: usize, options: &SolverOptions) -> Self {
        let zeros = || vec![0.0; dim];
        Dop853 {
            options: options.clone(),
            controller: PiController::new(1.0 / 8.0, 0.0, SAFE, FAC_MIN, FAC_MAX),
            st: Stages {
                k: std::array::from_fn(|_| zeros()),
            },
            y1: zeros(),
            ys: zeros(),
            dense: Dense {
                t_old: 0.0,
                h: 1.0,
                r: std::array::from_fn(|_| zeros()),
            },
            probe: PowerProbe::new(dim),
        }
    }

    fn start<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64],
        h_max: f64,
        stats: &mut Stats,
    ) -> Result<f64, Failure> {
        let [k1, k2, k3, ..] = &mut self.st.k;
        Ok(explicit_start(
            system,
            t0,
            y0,
            8,
            h_max,
            &self.options,
            k1,
            (k2, k3),
            stats,
        ))
    }

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Trial {
        self.st.step(system, t, h, y, &mut self.ys, &mut self.y1);
        stats.rhs_calls += 11;
        let (rtol, atol) = (self.options.rtol, &self.options.atol[..]);
        let e = h.abs() * error_estimate(&self.st.k, y, &self.y1, rtol, atol);
        if !e.is_finite() {
            // As in dp5: a non-finite trial means the step was far too large;
            // give up only when the state itself is already bad.
            if y.iter().any(|v| !v.is_finite()) {
                return Trial::Failed(Failure::NonFinite { t });
            }
            return Trial::Rejected {
                h_new: self.controller.after_non_finite(h),
            };
        }
        match self.controller.propose(e, h) {
            (true, h_new) => {
                // f at the new point: the stiffness test, the dense output
                // and (FSAL) the next step all need it.
                system.rhs(t + h, &self.y1, &mut self.st.k[12]);
                stats.rhs_calls += 1;
                Trial::Accepted { h_new }
            }
            (false, h_new) => Trial::Rejected { h_new },
        }
    }

    fn stiffness_indicator(&self, h: f64) -> f64 {
        // h·|λ| from stage 12 and the new point, which both sit at t + h.
        indicator(h, &self.st.k[12], &self.st.k[11], &self.y1, &self.ys)
    }

    fn power_check<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t_new: f64,
        h: f64,
        enough: f64,
        stats: &mut Stats,
    ) -> f64 {
        let (y1, fy, y_other) = (&self.y1, &self.st.k[12], &self.ys);
        let options = &self.options;
        self.probe
            .h_rho(system, t_new, y1, fy, y_other, h, options, enough, stats)
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        h: f64,
        y: &mut Vec<f64>,
        stats: &mut Stats,
    ) -> Result<(), Failure> {
        self.st
            .dense(system, t, h, y, &self.y1, &mut self.ys, &mut self.dense);
        stats.rhs_calls += 3;
        // FSAL: the derivative at the new point starts the next step.
        self.st.k.swap(0, 12);
        std::mem::swap(y, &mut self.y1);
        Ok(())
    }

    fn dense(&self) -> &dyn DenseOutput {
        &self.dense
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stage nodes c1…c16 (stage 13 is f at the end point, c = 1).
    const C: [f64; 16] = [
        0.0, C2, C3, C4, C5, C6, C7, C8, C9, C10, C11, 1.0, 1.0, C14, C15, C16,
    ];

    /// The Butcher matrix of all 16 stages, row i = stage i + 1.
    fn a() -> [[f64; 16]; 16] {
        let mut a = [[0.0; 16]; 16];
        let rows: [&[(usize, f64)]; 16] = [
            &[],
            &[(1, A21)],
            &[(1, A31), (2, A32)],
            &[(1, A41), (3, A43)],
            &[(1, A51), (3, A53), (4, A54)],
            &[(1, A61), (4, A64), (5, A65)],
            &[(1, A71), (4, A74), (5, A75), (6, A76)],
            &[(1, A81), (4, A84), (5, A85), (6, A86), (7, A87)],
            &[(1, A91), (4, A94), (5, A95), (6, A96), (7, A97), (8, A98)],
            &[
                (1, A101),
                (4, A104),
                (5, A105),
                (6, A106),
                (7, A107),
                (8, A108),
                (9, A109),
            ],
            &[
                (1, A111),
                (4, A114),
                (5, A115),
                (6, A116),
                (7, A117),
                (8, A118),
                (9, A119),
                (10, A1110),
            ],
            &[
                (1, A121),
                (4, A124),
                (5, A125),
                (6, A126),
                (7, A127),
                (8, A128),
                (9, A129),
                (10, A1210),
                (11, A1211),
            ],
            &[
                (1, B1),
                (6, B6),
                (7, B7),
                (8, B8),
                (9, B9),
                (10, B10),
                (11, B11),
                (12, B12),
            ],
            &[
                (1, A141),
                (7, A147),
                (8, A148),
                (9, A149),
                (10, A1410),
                (11, A1411),
                (12, A1412),
                (13, A1413),
            ],
            &[
                (1, A151),
                (6, A156),
                (7, A157),
                (8, A158),
                (11, A1511),
                (12, A1512),
                (13, A1513),
                (14, A1514),
            ],
            &[
                (1, A161),
                (6, A166),
                (7, A167),
                (8, A168),
                (9, A169),
                (13, A1613),
                (14, A1614),
                (15, A1615),
            ],
        ];
        for (i, row) in rows.iter().enumerate() {
            for &(j, v) in *row {
                a[i][j - 1] = v;
            }
        }
        a
    }

    /// Transcription check: consistency of every stage and the order
    /// conditions of the 8th-order weights, the 5th-order error weights and
    /// the 3rd-order weights (a wrong digit shows as a residual ≫ 1e-14).
    #[test]
    fn coefficients_satisfy_the_order_conditions() {
        let a = a();
        for i in 1..16 {
            let row: f64 = a[i].iter().sum();
            assert!(
                (row - C[i]).abs() < 1e-14,
                "row {}: {row} vs {}",
                i + 1,
                C[i]
            );
        }
        let b = a[12];
        for k in 0..8 {
            let s: f64 = (0..12).map(|i| b[i] * C[i].powi(k)).sum();
            assert!((s - 1.0 / f64::from(k + 1)).abs() < 1e-14, "b·c^{k}");
        }
        for k in 0..6 {
            let s: f64 = (0..12)
                .map(|i| b[i] * (0..12).map(|j| a[i][j] * C[j].powi(k)).sum::<f64>())
                .sum();
            let want = 1.0 / f64::from((k + 1) * (k + 2));
            assert!((s - want).abs() < 1e-14, "b·A·c^{k}: {s} vs {want}");
        }
        let er = [
            ER1, 0.0, 0.0, 0.0, 0.0, ER6, ER7, ER8, ER9, ER10, ER11, ER12,
        ];
        for k in 0..5 {
            let s: f64 = (0..12).map(|i| er[i] * C[i].powi(k)).sum();
            assert!(s.abs() < 1e-14, "er·c^{k} = {s}");
        }
        let bhh = [(0, BHH1), (8, BHH2), (11, BHH3)];
        for k in 0..3 {
            let s: f64 = bhh.iter().map(|&(i, w)| w * C[i].powi(k)).sum();
            assert!((s - 1.0 / f64::from(k + 1)).abs() < 1e-14, "bhh·c^{k}");
        }
    }
}
