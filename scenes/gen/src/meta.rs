//! `.meta` files: the importer settings Unity 2022.3 writes next to every asset.

/// A model's `.meta`: ModelImporter with Unity 2022's defaults, `fileIdsGeneration: 2`
/// (so mesh fileIDs are xxHash64 of `Type:Mesh-><name>0`), scale 1.
pub fn model(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\n{MODEL_IMPORTER}")
}

/// A `.mat` file's `.meta`: the material is object 2100000 of its file.
pub fn material(guid: &str) -> String {
    format!(
        "fileFormatVersion: 2\nguid: {guid}\nNativeFormatImporter:\n  externalObjects: {{}}\n  mainObjectFileID: 2100000\n{TAIL}"
    )
}

/// A TerrainData `.asset`'s `.meta`: the terrain is object 15600000 of its file.
pub fn terrain_data(guid: &str) -> String {
    format!(
        "fileFormatVersion: 2\nguid: {guid}\nNativeFormatImporter:\n  externalObjects: {{}}\n  mainObjectFileID: 15600000\n{TAIL}"
    )
}

/// A `.terrainlayer`'s `.meta`.
pub fn terrain_layer(guid: &str) -> String {
    format!(
        "fileFormatVersion: 2\nguid: {guid}\nNativeFormatImporter:\n  externalObjects: {{}}\n  mainObjectFileID: 8574412962073106934\n{TAIL}"
    )
}

/// A `.prefab`'s `.meta`.
pub fn prefab(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\nPrefabImporter:\n  externalObjects: {{}}\n{TAIL}")
}

/// A scene's `.meta`.
pub fn scene(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\nDefaultImporter:\n  externalObjects: {{}}\n{TAIL}")
}

/// A folder's `.meta`.
pub fn folder(guid: &str) -> String {
    format!(
        "fileFormatVersion: 2\nguid: {guid}\nfolderAsset: yes\nDefaultImporter:\n  externalObjects: {{}}\n{TAIL}"
    )
}

/// How a texture is imported: the TextureImporter settings the generated scenes vary.
#[derive(Clone, Copy, Debug)]
pub struct TextureImport {
    /// `filterMode`: 0 point, 1 bilinear, 2 trilinear.
    pub filter: u8,
    pub mipmaps: bool,
    pub srgb: bool,
    /// `wrapU`/`wrapV`: 0 repeat, 1 clamp.
    pub wrap: u8,
    pub alpha_is_transparency: bool,
    /// Texture Type "Normal map" (`textureType: 1`).
    pub normal_map: bool,
}

/// A texture's `.meta`: TextureImporter as Unity 2022.3 writes it for a Default texture.
pub fn texture(guid: &str, im: &TextureImport) -> String {
    let b = |x: bool| x as u8;
    format!(
        "fileFormatVersion: 2
guid: {guid}
TextureImporter:
  internalIDToNameTable: []
  externalObjects: {{}}
  serializedVersion: 12
  mipmaps:
    mipMapMode: 0
    enableMipMap: {mips}
    sRGBTexture: {srgb}
    linearTexture: 0
    fadeOut: 0
    borderMipMap: 0
    mipMapsPreserveCoverage: 0
    alphaTestReferenceValue: 0.5
    mipMapFadeDistanceStart: 1
    mipMapFadeDistanceEnd: 3
  bumpmap:
    convertToNormalMap: 0
    externalNormalMap: 0
    heightScale: 0.25
    normalMapFilter: 0
    flipGreenChannel: 0
  isReadable: 0
  streamingMipmaps: 0
  streamingMipmapsPriority: 0
  vTOnly: 0
  ignoreMipmapLimit: 0
  grayScaleToAlpha: 0
  generateCubemap: 6
  cubemapConvolution: 0
  seamlessCubemap: 0
  textureFormat: 1
  maxTextureSize: 2048
  textureSettings:
    serializedVersion: 2
    filterMode: {filter}
    aniso: 1
    mipBias: 0
    wrapU: {wrap}
    wrapV: {wrap}
    wrapW: {wrap}
  nPOTScale: 1
  lightmap: 0
  compressionQuality: 50
  spriteMode: 0
  spriteExtrude: 1
  spriteMeshType: 1
  alignment: 0
  spritePivot: {{x: 0.5, y: 0.5}}
  spritePixelsToUnits: 100
  spriteBorder: {{x: 0, y: 0, z: 0, w: 0}}
  spriteGenerateFallbackPhysicsShape: 1
  alphaUsage: 1
  alphaIsTransparency: {ait}
  spriteTessellationDetail: -1
  textureType: {kind}
  textureShape: 1
  singleChannelComponent: 0
  flipbookRows: 1
  flipbookColumns: 1
  maxTextureSizeSet: 0
  compressionQualitySet: 0
  textureFormatSet: 0
  ignorePngGamma: 0
  applyGammaDecoding: 0
  swizzle: 50462976
  cookieLightType: 0
  platformSettings:
  - serializedVersion: 3
    buildTarget: DefaultTexturePlatform
    maxTextureSize: 2048
    resizeAlgorithm: 0
    textureFormat: -1
    textureCompression: 1
    compressionQuality: 50
    crunchedCompression: 0
    allowsAlphaSplitting: 0
    overridden: 0
    ignorePlatformSupport: 0
    androidETC2FallbackOverride: 0
    forceMaximumCompressionQuality_BC6H_BC7: 0
  spriteSheet:
    serializedVersion: 2
    sprites: []
    outline: []
    physicsShape: []
    bones: []
    spriteID: 
    internalID: 0
    vertices: []
    indices: 
    edges: []
    weights: []
    secondaryTextures: []
    nameFileIdTable: {{}}
  mipmapLimitGroupName: 
  pSDRemoveMatte: 0
{TAIL}",
        mips = b(im.mipmaps),
        srgb = b(im.srgb),
        filter = im.filter,
        wrap = im.wrap,
        ait = b(im.alpha_is_transparency),
        kind = b(im.normal_map),
    )
}

// Unity writes these three keys with a trailing space when they are empty.
const TAIL: &str = "  userData: \n  assetBundleName: \n  assetBundleVariant: \n";

const MODEL_IMPORTER: &str = "ModelImporter:
  serializedVersion: 22200
  internalIDToNameTable: []
  externalObjects: {}
  materials:
    materialImportMode: 2
    materialName: 0
    materialSearch: 1
    materialLocation: 1
  animations:
    legacyGenerateAnimations: 4
    bakeSimulation: 0
    resampleCurves: 1
    optimizeGameObjects: 0
    removeConstantScaleCurves: 0
    motionNodeName: 
    animationImportErrors: 
    animationImportWarnings: 
    animationRetargetingWarnings: 
    animationDoRetargetingWarnings: 0
    importAnimatedCustomProperties: 0
    importConstraints: 0
    animationCompression: 1
    animationRotationError: 0.5
    animationPositionError: 0.5
    animationScaleError: 0.5
    animationWrapMode: 0
    extraExposedTransformPaths: []
    extraUserProperties: []
    clipAnimations: []
    isReadable: 1
  meshes:
    lODScreenPercentages: []
    globalScale: 1
    meshCompression: 0
    addColliders: 0
    useSRGBMaterialColor: 1
    sortHierarchyByName: 1
    importPhysicalCameras: 1
    importVisibility: 1
    importBlendShapes: 1
    importCameras: 1
    importLights: 1
    nodeNameCollisionStrategy: 1
    fileIdsGeneration: 2
    swapUVChannels: 0
    generateSecondaryUV: 0
    useFileUnits: 1
    keepQuads: 0
    weldVertices: 1
    bakeAxisConversion: 0
    preserveHierarchy: 0
    skinWeightsMode: 0
    maxBonesPerVertex: 4
    minBoneWeight: 0.001
    optimizeBones: 1
    meshOptimizationFlags: -1
    indexFormat: 0
    secondaryUVAngleDistortion: 8
    secondaryUVAreaDistortion: 15.000001
    secondaryUVHardAngle: 88
    secondaryUVMarginMethod: 1
    secondaryUVMinLightmapResolution: 40
    secondaryUVMinObjectScale: 1
    secondaryUVPackMargin: 4
    useFileScale: 1
    strictVertexDataChecks: 0
  tangentSpace:
    normalSmoothAngle: 60
    normalImportMode: 0
    tangentImportMode: 3
    normalCalculationMode: 4
    legacyComputeAllNormalsFromSmoothingGroupsWhenMeshHasBlendShapes: 0
    blendShapeNormalImportMode: 1
    normalSmoothingSource: 0
  referencedClips: []
  importAnimation: 1
  humanDescription:
    serializedVersion: 3
    human: []
    skeleton: []
    armTwist: 0.5
    foreArmTwist: 0.5
    upperLegTwist: 0.5
    legTwist: 0.5
    armStretch: 0.05
    legStretch: 0.05
    feetSpacing: 0
    globalScale: 1
    rootMotionBoneName: 
    hasTranslationDoF: 0
    hasExtraRoot: 0
    skeletonHasParents: 1
  lastHumanDescriptionAvatarSource: {instanceID: 0}
  autoGenerateAvatarMappingIfUnspecified: 1
  animationType: 2
  humanoidOversampling: 1
  avatarSetup: 0
  addHumanoidExtraRootOnlyWhenUsingAvatar: 1
  importBlendShapeDeformPercent: 1
  remapMaterialsIfMaterialImportModeIsNone: 0
  additionalBone: 0
  userData: 
  assetBundleName: 
  assetBundleVariant: 
";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_meta_has_the_keys_the_converter_reads() {
        let m = model("0123456789abcdef0123456789abcdef");
        assert!(m.starts_with("fileFormatVersion: 2\nguid: 0123456789abcdef0123456789abcdef\nModelImporter:\n  serializedVersion: 22200\n  internalIDToNameTable: []\n"));
        for key in [
            "    fileIdsGeneration: 2\n",
            "    globalScale: 1\n",
            "    useFileScale: 1\n",
        ] {
            assert!(m.contains(key), "missing {key:?}");
        }
        assert!(m.ends_with("  assetBundleVariant: \n"));
    }

    #[test]
    fn material_meta_names_the_main_object() {
        let m = material("00000000000000000000000000000001");
        assert!(m.contains(
            "NativeFormatImporter:\n  externalObjects: {}\n  mainObjectFileID: 2100000\n"
        ));
    }
}
