"""The module OpenUSD's plugin system imports for the ``usdRenderLint``
validators (``"Type": "python"`` in usdrender_lint/usdplugin/plugInfo.json):
importing it registers their task functions, like a C++ plugin's
``TF_REGISTRY_FUNCTION(UsdValidationRegistry)``. Nothing else imports it."""

from usdrender_lint.usdplugin.validators import register_validators

REGISTERED = register_validators()
