// placeholder: issue #3
